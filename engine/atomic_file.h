// Writes that never leave a half-written file in place of a good one: the bytes go to a
// temporary file in the same directory, are flushed, and only then renamed over the target.
#pragma once

#include <string>
#include <string_view>

namespace ballpit {

// Throws ballpit::Error naming the path if any step fails; the old file is then untouched.
void write_file_atomically(const std::string& path, std::string_view bytes);

}  // namespace ballpit
