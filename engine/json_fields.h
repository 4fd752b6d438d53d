// Strict reading of one JSON object of a scene file: unknown keys are refused up front, known
// ones are read on demand with their type and range checked, and every error reads
// "SOURCE: FIELD.PATH: expected ..., got ..." so a user can fix the file without the source.
// Missing keys leave the output as it was (the default).
#pragma once

#include <cstdint>
#include <initializer_list>
#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "engine/math.h"

namespace ballpit {

using Json = nlohmann::ordered_json;

// "number 1.5", "string \"big\"", "array [1,2]": what a value is, for "got ..." in messages.
std::string json_type_name(const Json& v);
std::string number_text(double x);

// RGBA8 colour (red in the low byte, as the sphere table stores it) <-> "#rrggbb".
std::string color_text(std::uint32_t rgba);

// Throws ballpit::Error "SOURCE: FIELD.PATH: WHAT".
[[noreturn]] void scene_error(const std::string& source, const std::string& field_path, const std::string& what);

inline constexpr float kNoLimit = std::numeric_limits<float>::max();

class JsonFields {
 public:
  // Throws if `object` is not an object or holds a key not in `known`.
  JsonFields(const Json& object, std::string path, const std::string& source, std::vector<std::string> known);

  [[noreturn]] void fail(const std::string& field_path, const std::string& what) const;
  // The path of one of this object's keys ("pit.half_width"), or of a list element ("path.2").
  std::string field(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }
  const Json* find(const std::string& key) const;
  const std::string& source() const { return source_; }

  // A finite number in [lo, hi] (open at lo when lo_open); `unit` goes into the message.
  void number(const std::string& key, float& out, float lo, float hi, bool lo_open, const char* unit) const;
  template <class Int>
  void integer(const std::string& key, Int& out, long long lo, long long hi) const {
    if (const Json* v = find(key)) out = static_cast<Int>(checked_integer(key, *v, lo, hi));
  }
  void boolean(const std::string& key, bool& out) const;
  void vec3(const std::string& key, Vec3& out, const char* unit) const;
  void text(const std::string& key, std::string& out) const;  // a non-empty string
  // One of `choices` (a string); `out` becomes its index.
  void choice(const std::string& key, int& out, std::initializer_list<const char*> choices) const;
  void color(const std::string& key, std::uint32_t& out) const;  // "#rrggbb"

  // The same checks for a value that is not under a key of this object (a list element, or a
  // key whose value may take several shapes); `field_path` names it in errors.
  float number_value(const std::string& field_path, const Json& v, float lo, float hi, bool lo_open,
                     const char* unit) const;

 private:
  long long checked_integer(const std::string& key, const Json& v, long long lo, long long hi) const;

  const Json& object_;
  std::string path_;
  const std::string& source_;
};

}  // namespace ballpit
