// Writes that never leave a half-written file in place of a good one: the bytes go to a
// temporary file in the same directory, are flushed, and only then renamed over the target.
#pragma once

#include <string>
#include <string_view>

namespace ballpit {

// Throws ballpit::Error naming the path if any step fails; the old file is then untouched.
void write_file_atomically(const std::string& path, std::string_view bytes);

// Throws ballpit::Error naming the path if write_file_atomically could not write it: its folder
// is missing or refuses a new file, or the path is a folder. A run checks its output paths
// before it starts, so a typo costs a second, not the whole run's results.
void check_writable(const std::string& path);

}  // namespace ballpit
