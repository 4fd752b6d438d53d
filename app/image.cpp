#include "app/image.h"

#include <png.h>

#include <cstring>
#include <fstream>
#include <sstream>

#include "engine/atomic_file.h"
#include "engine/error.h"

namespace ballpit {

namespace {

// libpng reports an error through a callback that must not return. Throwing through libpng's C
// frames is undefined, so the callback records the message and longjmps back to setjmp in
// encode_rows / decode_rows, which hold no C++ objects with destructors across the jump.
struct PngErrors {
  std::string message;
};

void on_png_error(png_structp png, png_const_charp msg) {
  auto* e = static_cast<PngErrors*>(png_get_error_ptr(png));
  e->message = msg;
  png_longjmp(png, 1);
}
void on_png_warning(png_structp, png_const_charp) {}

void append_bytes(png_structp png, png_bytep data, png_size_t n) {
  auto* out = static_cast<std::string*>(png_get_io_ptr(png));
  out->append(reinterpret_cast<const char*>(data), n);
}
void flush_nothing(png_structp) {}

struct Reader {
  const std::string* bytes;
  std::size_t offset;
};
void read_bytes(png_structp png, png_bytep data, png_size_t n) {
  auto* r = static_cast<Reader*>(png_get_io_ptr(png));
  if (r->offset + n > r->bytes->size()) png_error(png, "unexpected end of data (truncated PNG)");
  std::memcpy(data, r->bytes->data() + r->offset, n);
  r->offset += n;
}

// Does the libpng calls with no C++ objects alive between setjmp and a possible longjmp.
bool encode_rows(const Image& image, std::string* out, PngErrors* errors) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, errors, on_png_error, on_png_warning);
  if (!png) return false;
  png_infop info = png_create_info_struct(png);
  if (!info || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_set_write_fn(png, out, append_bytes, flush_nothing);
  png_set_IHDR(png, info, static_cast<png_uint_32>(image.width), static_cast<png_uint_32>(image.height), 8,
               PNG_COLOR_TYPE_RGBA, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_compression_level(png, 6);
  png_write_info(png, info);
  for (int y = 0; y < image.height; ++y)
    png_write_row(png, const_cast<png_bytep>(image.pixel(0, y)));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

bool decode_rows(const std::string& bytes, Image* image, PngErrors* errors) {
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, errors, on_png_error, on_png_warning);
  if (!png) return false;
  png_infop info = png_create_info_struct(png);
  if (!info || setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    return false;
  }
  Reader reader{&bytes, 0};
  png_set_read_fn(png, &reader, read_bytes);
  png_read_info(png, info);
  // Whatever the file holds, hand back 8-bit RGBA.
  png_set_expand(png);
  png_set_strip_16(png);
  png_set_gray_to_rgb(png);
  png_set_add_alpha(png, 0xff, PNG_FILLER_AFTER);
  png_read_update_info(png, info);
  image->width = static_cast<int>(png_get_image_width(png, info));
  image->height = static_cast<int>(png_get_image_height(png, info));
  if (png_get_rowbytes(png, info) != static_cast<png_size_t>(image->width) * 4)
    png_error(png, "unsupported pixel layout");
  image->rgba.resize(static_cast<std::size_t>(image->width) * image->height * 4);
  for (int y = 0; y < image->height; ++y) png_read_row(png, &image->rgba[static_cast<std::size_t>(y) * image->width * 4], nullptr);
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  return true;
}

}  // namespace

std::string encode_png(const Image& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.rgba.size() != static_cast<std::size_t>(image.width) * image.height * 4)
    throw Error("PNG: image of " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                " pixels does not match its " + std::to_string(image.rgba.size()) + " bytes");
  std::string out;
  PngErrors errors;
  if (!encode_rows(image, &out, &errors)) throw Error("PNG: libpng could not encode the image: " + errors.message);
  return out;
}

Image decode_png(const std::string& bytes, const std::string& what) {
  if (bytes.size() < 8 || png_sig_cmp(reinterpret_cast<png_const_bytep>(bytes.data()), 0, 8) != 0)
    throw Error(what + ": not a PNG file");
  Image image;
  PngErrors errors;
  if (!decode_rows(bytes, &image, &errors)) throw Error(what + ": " + errors.message);
  return image;
}

void write_png(const std::string& path, const Image& image) { write_file_atomically(path, encode_png(image)); }

Image read_png(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot open for reading");
  std::ostringstream s;
  s << in.rdbuf();
  return decode_png(s.str(), path);
}

}  // namespace ballpit
