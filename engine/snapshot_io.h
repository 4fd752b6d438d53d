// The snapshot payload's primitives (engine/snapshot.h): little-endian raw values, arrays as a
// u64 count then their bytes, strings likewise. The Reader bounds-checks every read and names
// the field it was reading, so a damaged file is refused by field, never read past its end.
// Internal to the snapshot code (snapshot.cpp, character_snapshot.cpp).
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "engine/contact_set.h"
#include "engine/error.h"
#include "engine/math.h"

namespace ballpit::snapshot_io {

// The header's checksum of the payload: FNV-1a, 64 bit (also used by the snapshot fuzzer to
// get past the check).
inline std::uint64_t payload_checksum(std::string_view bytes) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 0x100000001b3ull;
  }
  return h;
}

// The header before the payload: magic[8], u32 version, u32 reserved, u64 payload bytes, u64
// payload_checksum. Byte offsets of the fields a reader checks.
inline constexpr std::size_t kHeaderBytes = 8 + 4 + 4 + 8 + 8;
inline constexpr std::size_t kVersionAt = 8, kPayloadSizeAt = 16, kChecksumAt = 24;

// Makes a file's header state the size and checksum of the payload after it. For those who edit
// a payload on purpose (the tests' older-version files, the fuzzer's mutations); the encoder
// writes its own header.
inline void reseal_header(std::string& file) {
  const std::string_view payload = std::string_view(file).substr(kHeaderBytes);
  const std::uint64_t size = payload.size(), checksum = payload_checksum(payload);
  std::memcpy(file.data() + kPayloadSizeAt, &size, sizeof size);
  std::memcpy(file.data() + kChecksumAt, &checksum, sizeof checksum);
}

static_assert(std::endian::native == std::endian::little, "snapshots are written little-endian");
static_assert(sizeof(Vec3) == 12 && sizeof(WarmStartEntry) == 20, "stored as raw bytes: no padding");
static_assert(sizeof(Quat) == 16 && sizeof(Mat4) == 64 && sizeof(Affine3) == 64, "stored as raw bytes: no padding");

// Types stored as their bytes. Eigen's fixed-size types are not formally trivially copyable but
// are packed floats (asserted above).
template <class T>
constexpr bool kRawBytes = std::is_trivially_copyable_v<T> || std::is_same_v<T, Vec3> ||
                           std::is_same_v<T, WarmStartEntry> || std::is_same_v<T, Quat> ||
                           std::is_same_v<T, Mat4> || std::is_same_v<T, Affine3>;

struct Writer {
  std::string out;
  template <class T>
  void put(const T& v) {
    static_assert(kRawBytes<T>);
    out.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  template <class T>
  void array(std::span<const T> a) {
    static_assert(kRawBytes<T>);
    put(static_cast<std::uint64_t>(a.size()));
    out.append(reinterpret_cast<const char*>(a.data()), a.size_bytes());
  }
  template <class T>
  void array(const std::vector<T>& a) {
    array(std::span<const T>(a));
  }
  void text(std::string_view s) { array(std::span<const char>(s.data(), s.size())); }
};

// Reads fields in order; every read is bounds-checked and names the field it was reading.
struct Reader {
  std::string_view in;
  std::size_t at = 0;
  const std::string& path;

  [[noreturn]] void fail(const std::string& what) const { throw Error("snapshot '" + path + "': " + what); }
  template <class T>
  T get(const char* field) {
    if (in.size() - at < sizeof(T))
      fail("payload ends inside field '" + std::string(field) + "' (offset " + std::to_string(at) + ")");
    static_assert(kRawBytes<T>);
    T v;
    std::memcpy(static_cast<void*>(&v), in.data() + at, sizeof v);
    at += sizeof v;
    return v;
  }
  template <class T>
  void array(const char* field, std::vector<T>& a) {
    const std::uint64_t n = get<std::uint64_t>(field);
    if (n > (in.size() - at) / sizeof(T))
      fail("field '" + std::string(field) + "' claims " + std::to_string(n) + " elements, more than the payload holds");
    a.resize(static_cast<std::size_t>(n));
    if (n) std::memcpy(static_cast<void*>(a.data()), in.data() + at, n * sizeof(T));
    at += n * sizeof(T);
  }
  std::string text(const char* field) {
    std::vector<char> chars;
    array(field, chars);
    return {chars.begin(), chars.end()};
  }
  // A count of elements each at least `min_bytes` long: refused before anything is allocated
  // if the payload cannot hold that many.
  std::uint64_t count(const char* field, std::size_t min_bytes) {
    const std::uint64_t n = get<std::uint64_t>(field);
    if (n > (in.size() - at) / min_bytes)
      fail("field '" + std::string(field) + "' claims " + std::to_string(n) + " elements, more than the payload holds");
    return n;
  }
};

}  // namespace ballpit::snapshot_io
