#include "engine/json_fields.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "engine/error.h"

namespace ballpit {

std::string json_type_name(const Json& v) {
  // Appended, not "string " + dump(): GCC 12 warns (-Wrestrict) on that inlined insert.
  std::string name = v.is_number_integer() ? "integer" : v.is_number() ? "number" : v.type_name();
  // A --set value that is not JSON becomes a string as typed, invalid UTF-8 included, and
  // dump() throws json::type_error on that: replace such bytes (U+FFFD), so the user still
  // gets the message naming the field instead of a JSON library exception.
  if (!v.is_null()) name.append(" ").append(v.dump(-1, ' ', false, Json::error_handler_t::replace));
  return name;
}

std::string number_text(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

std::string color_text(std::uint32_t rgba) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x", rgba & 0xffu, (rgba >> 8) & 0xffu, (rgba >> 16) & 0xffu);
  return buf;
}

JsonFields::JsonFields(const Json& object, std::string path, const std::string& source, std::vector<std::string> known)
    : object_(object), path_(std::move(path)), source_(source) {
  if (!object.is_object()) fail(path_, "expected an object, got " + json_type_name(object));
  for (const auto& [key, value] : object.items()) {
    bool ok = false;
    for (const std::string& k : known) ok = ok || k == key;
    if (!ok) {
      std::string list;
      for (const std::string& k : known) list += (list.empty() ? "" : ", ") + k;
      fail(field(key), "unknown key (known keys here: " + list + ")");
    }
  }
}

void scene_error(const std::string& source, const std::string& field_path, const std::string& what) {
  throw Error(source + ": " + (field_path.empty() ? std::string("(top level)") : field_path) + ": " + what);
}

void JsonFields::fail(const std::string& field_path, const std::string& what) const {
  scene_error(source_, field_path, what);
}

const Json* JsonFields::find(const std::string& key) const {
  auto it = object_.find(key);
  return it == object_.end() ? nullptr : &*it;
}

float JsonFields::number_value(const std::string& at, const Json& v, float lo, float hi, bool lo_open,
                               const char* unit) const {
  if (!v.is_number()) fail(at, std::string("expected a number (") + unit + "), got " + json_type_name(v));
  const double x = v.get<double>();
  const bool ok = std::isfinite(x) && (lo_open ? x > lo : x >= lo) && x <= hi;
  if (!ok) {
    std::ostringstream range;
    range << (lo_open ? "> " : ">= ") << lo;
    if (hi < kNoLimit) range << " and <= " << hi;
    fail(at, "expected a number " + range.str() + " (" + unit + "), got " + v.dump());
  }
  return static_cast<float>(x);
}

void JsonFields::number(const std::string& key, float& out, float lo, float hi, bool lo_open, const char* unit) const {
  if (const Json* v = find(key)) out = number_value(field(key), *v, lo, hi, lo_open, unit);
}

long long JsonFields::checked_integer(const std::string& key, const Json& v, long long lo, long long hi) const {
  if (!v.is_number_integer()) fail(field(key), "expected an integer, got " + json_type_name(v));
  const long long x = v.get<long long>();
  if (x < lo || x > hi || (v.is_number_unsigned() && v.get<unsigned long long>() > static_cast<unsigned long long>(hi)))
    fail(field(key), "expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " + v.dump());
  return x;
}

void JsonFields::boolean(const std::string& key, bool& out) const {
  const Json* v = find(key);
  if (!v) return;
  if (!v->is_boolean()) fail(field(key), "expected true or false, got " + json_type_name(*v));
  out = v->get<bool>();
}

void JsonFields::vec3(const std::string& key, Vec3& out, const char* unit) const {
  const Json* v = find(key);
  if (!v) return;
  if (!v->is_array() || v->size() != 3)
    fail(field(key), std::string("expected [x, y, z] (") + unit + "), got " + json_type_name(*v));
  for (int a = 0; a < 3; ++a) {
    const Json& c = (*v)[static_cast<std::size_t>(a)];
    // Finite as a float too: 1e300 is a finite double, but beyond the float the engine keeps.
    if (!c.is_number() || !(std::abs(c.get<double>()) <= std::numeric_limits<float>::max()))
      fail(field(key) + "[" + std::to_string(a) + "]", "expected a finite number, got " + json_type_name(c));
    out[a] = c.get<float>();
  }
}

void JsonFields::text(const std::string& key, std::string& out) const {
  const Json* v = find(key);
  if (!v) return;
  if (!v->is_string() || v->get<std::string>().empty())
    fail(field(key), "expected a non-empty string, got " + json_type_name(*v));
  out = v->get<std::string>();
}

void JsonFields::choice(const std::string& key, int& out, std::initializer_list<const char*> choices) const {
  const Json* v = find(key);
  if (!v) return;
  int i = 0;
  std::string list;
  for (const char* c : choices) {
    if (v->is_string() && *v == c) {
      out = i;
      return;
    }
    if (i > 0) list.append(i + 1 == static_cast<int>(choices.size()) ? " or " : ", ");
    list.append("\"").append(c).append("\"");
    ++i;
  }
  fail(field(key), "expected " + list + ", got " + json_type_name(*v));
}

void JsonFields::color(const std::string& key, std::uint32_t& out) const {
  const Json* v = find(key);
  if (!v) return;
  const std::string s = v->is_string() ? v->get<std::string>() : std::string();
  bool ok = s.size() == 7 && s[0] == '#';
  for (std::size_t i = 1; ok && i < s.size(); ++i) ok = std::isxdigit(static_cast<unsigned char>(s[i])) != 0;
  if (!ok) fail(field(key), "expected a colour \"#rrggbb\", got " + json_type_name(*v));
  const auto rgb = static_cast<std::uint32_t>(std::stoul(s.substr(1), nullptr, 16));
  out = 0xff000000u | ((rgb & 0xffu) << 16) | (rgb & 0xff00u) | ((rgb >> 16) & 0xffu);
}

}  // namespace ballpit
