// Replays inputs through a fuzz target without libFuzzer, for the normal build's ctest: every
// file named (or found in a folder named) on the command line goes to the target's
// LLVMFuzzerTestOneInput, which swallows ballpit::Error, the clean failure. Anything else
// escaping is a regression; crashes and sanitizer reports end the process by themselves.
#include <algorithm>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fuzz/fuzz_target.h"

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  std::vector<fs::path> inputs;
  for (int i = 1; i < argc; ++i) {
    const fs::path arg = argv[i];
    if (fs::is_directory(arg)) {
      for (const auto& entry : fs::recursive_directory_iterator(arg))
        if (entry.is_regular_file()) inputs.push_back(entry.path());
    } else if (fs::is_regular_file(arg)) {
      inputs.push_back(arg);
    } else {
      std::fprintf(stderr, "replay: %s is neither a file nor a folder\n", argv[i]);
      return 2;
    }
  }
  std::sort(inputs.begin(), inputs.end());  // a stable order, so a failure reproduces as it was
  if (inputs.empty()) {
    std::fprintf(stderr, "replay: no inputs (expected files or folders of them)\n");
    return 2;
  }
  for (const fs::path& path : inputs) {
    std::ifstream in(path, std::ios::binary);
    const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    std::fprintf(stderr, "replay: %s (%zu bytes)\n", path.c_str(), bytes.size());
    try {
      LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
    } catch (const std::exception& e) {
      std::fprintf(stderr, "replay: FAILED %s: an exception other than ballpit::Error escaped: %s\n", path.c_str(),
                   e.what());
      return 1;
    } catch (...) {
      std::fprintf(stderr, "replay: FAILED %s: a non-standard exception escaped\n", path.c_str());
      return 1;
    }
  }
  std::fprintf(stderr, "replay: %zu inputs, each loaded or refused with ballpit::Error\n", inputs.size());
  return 0;
}
