#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "fuzz/fuzz_target.h"

namespace ballpit::fuzz {

TempFile::TempFile(std::string_view suffix) {
  static int counter = 0;
  path_ = (std::filesystem::temp_directory_path() /
           ("ballpit_fuzz_" + std::to_string(::getpid()) + "_" + std::to_string(counter++) + std::string(suffix)))
              .string();
}

TempFile::~TempFile() {
  std::error_code ec;
  std::filesystem::remove(path_, ec);
}

void TempFile::write(std::string_view bytes) const {
  std::ofstream out(path_, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out.flush()) {
    std::fprintf(stderr, "fuzz harness: cannot write the temporary file %s\n", path_.c_str());
    std::abort();
  }
}

}  // namespace ballpit::fuzz
