// Screenshots as PNG: encoding round-trips exactly, bad input is an error naming the file,
// and a write that cannot finish leaves nothing behind.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "app/image.h"
#include "engine/error.h"

using namespace ballpit;

namespace {

Image gradient(int w, int h) {
  Image im;
  im.width = w;
  im.height = h;
  im.rgba.resize(static_cast<std::size_t>(w) * h * 4);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      std::uint8_t* p = &im.rgba[(static_cast<std::size_t>(y) * w + x) * 4];
      p[0] = static_cast<std::uint8_t>(x * 7);
      p[1] = static_cast<std::uint8_t>(y * 13);
      p[2] = static_cast<std::uint8_t>(x ^ y);
      p[3] = 255;
    }
  return im;
}

std::filesystem::path scratch(const std::string& name) {
  auto dir = std::filesystem::temp_directory_path() / ("ballpit_test_image_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir / name;
}

}  // namespace

TEST(Png, EncodingRoundTripsEveryPixel) {
  Image im = gradient(37, 23);
  Image back = decode_png(encode_png(im));
  EXPECT_EQ(back.width, 37);
  EXPECT_EQ(back.height, 23);
  EXPECT_EQ(back.rgba, im.rgba);
}

TEST(Png, WriteThenReadGivesTheSameImageAndNoTemporaryFile) {
  auto path = scratch("shot.png");
  write_png(path.string(), gradient(16, 9));
  EXPECT_EQ(read_png(path.string()).rgba, gradient(16, 9).rgba);
  for (const auto& entry : std::filesystem::directory_iterator(path.parent_path()))
    EXPECT_EQ(entry.path().filename(), "shot.png") << "left behind: " << entry.path();
  std::filesystem::remove_all(path.parent_path());
}

TEST(Png, AnUnwritablePathIsAnErrorNamingItAndLeavesNoFile) {
  auto path = scratch("no_such_dir") / "shot.png";
  try {
    write_png(path.string(), gradient(4, 4));
    FAIL() << "expected ballpit::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_dir"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(path));
  std::filesystem::remove_all(path.parent_path().parent_path());
}

TEST(Png, TruncatedOrForeignBytesAreAClearError) {
  std::string png = encode_png(gradient(8, 8));
  EXPECT_THROW(decode_png(png.substr(0, png.size() / 2), "half.png"), Error);
  try {
    decode_png("GIF89a not a png", "cat.gif");
    FAIL() << "expected ballpit::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cat.gif: not a PNG"), std::string::npos) << e.what();
  }
}

TEST(Png, AnImageWhoseBytesDoNotMatchItsSizeIsRejected) {
  Image im = gradient(4, 4);
  im.rgba.pop_back();
  EXPECT_THROW(encode_png(im), Error);
}
