// The model probe: assimp reads a model file first in a process of its own, the
// ballpit-model-probe executable, and import_model reads it only if that process survived.
// assimp crashes on some damaged files (fuzzing found a .X file that makes its parser follow a
// null pointer) and loops on others, and neither can be caught inside the process that reads.
// Decision: the probe is a fresh program, started with posix_spawn, never a fork of the caller.
// A fork copies the caller's memory with every lock another thread held at that moment and no
// thread to release it; the app imports while the scheduler's and OpenMP's threads run, and a
// forked reader once waited for good on the allocator's lock (AddressSanitizer's).
#pragma once

#include <chrono>
#include <string>

namespace ballpit {

// The probe's exit statuses. Anything else (a signal, a sanitizer's exit after a report) is a
// crash.
inline constexpr int kProbeRead = 0;     // assimp read the file
inline constexpr int kProbeUsage = 2;    // the probe was started wrongly
inline constexpr int kProbeRefused = 3;  // assimp refused it cleanly (import_model says why)

// How the probe is run: the build's own program unless a test names another, and how long it
// may read. Four seconds is forty times what the Wuson takes (about 0.1 s, with or without
// AddressSanitizer); a probe still reading then is stuck or lost in a damaged file, and the
// import would be too. A minute was too long: fuzzing found a 2.8 KB .X file
// (tests/fuzz_regressions/model_import/slow_8gb_skin_weights.x) that assimp reads for 23 s,
// growing to 8.4 GB, before refusing it, and the import then read it again to say why. The
// limit is under half of the fuzzer's 10 s per input, which a refusal must fit.
struct ProbeSettings {
  std::string program;  // empty: this build's ballpit-model-probe
  std::chrono::milliseconds time_limit{4'000};
};

// Throws ballpit::Error for a model file it refuses: "model file 'PATH': WHAT". The importer
// and the probe word every refusal so.
[[noreturn]] void fail_model_file(const std::string& path, const std::string& what);

// In the importing process: runs the probe on `path` with assimp's post-processing `flags` and
// throws ballpit::Error naming the file if assimp crashed on it or did not finish within the
// time limit, or if the probe program is missing.
void refuse_if_it_crashes_assimp(const std::string& path, unsigned flags, const ProbeSettings& probe = {});

// In the probe process: assimp reads the file; returns the exit status for it.
int read_in_probe(const char* path, unsigned flags);

}  // namespace ballpit
