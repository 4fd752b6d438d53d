// ballpit-model-probe FLAGS FILE: assimp reads a model file in this process, so that a file
// that crashes assimp takes down only this process (engine/model_probe.h).
#include <cerrno>
#include <cstdio>
#include <cstdlib>

#include "engine/model_probe.h"

int main(int argc, char** argv) {
  char* end = nullptr;
  errno = 0;
  const unsigned long flags = argc == 3 ? std::strtoul(argv[1], &end, 10) : 0;
  if (argc != 3 || end == argv[1] || *end != '\0' || errno != 0) {
    std::fprintf(stderr, "usage: %s FLAGS FILE (assimp's post-processing flags, a model file)\n", argv[0]);
    return ballpit::kProbeUsage;
  }
  const int verdict = ballpit::read_in_probe(argv[2], static_cast<unsigned>(flags));
  // The verdict is the exit status and nothing may change it: in a sanitized build the leak
  // check at exit would (assimp leaks what it built of a file it refuses, scripts/lsan.supp).
  std::_Exit(verdict);
}
