// ballpit-model-probe FLAGS MEMORY_MB FILE: assimp reads a model file in this process, so that a
// file that crashes assimp, or swells it past MEMORY_MB of address space, takes down only this
// process (engine/model_probe.h).
#include <cerrno>
#include <cstdio>
#include <cstdlib>

#include "engine/model_probe.h"

namespace {

// A whole decimal number, or false.
bool parse_count(const char* text, unsigned long& value) {
  char* end = nullptr;
  errno = 0;
  value = std::strtoul(text, &end, 10);
  return end != text && *end == '\0' && errno == 0 && text[0] != '-';
}

}  // namespace

int main(int argc, char** argv) {
  unsigned long flags = 0, megabytes = 0;
  if (argc != 4 || !parse_count(argv[1], flags) || !parse_count(argv[2], megabytes) || megabytes == 0) {
    std::fprintf(stderr, "usage: %s FLAGS MEMORY_MB FILE (assimp's post-processing flags, the most memory it may use, a model file)\n",
                 argv[0]);
    return ballpit::kProbeUsage;
  }
  ballpit::limit_probe_memory(megabytes);
  const int verdict = ballpit::read_in_probe(argv[3], static_cast<unsigned>(flags));
  // The verdict is the exit status and nothing may change it: in a sanitized build the leak
  // check at exit would (assimp leaks what it built of a file it refuses, scripts/lsan.supp).
  std::_Exit(verdict);
}
