// The model probe: assimp reads a model file first in a process of its own, the
// ballpit-model-probe executable, and import_model reads it only if assimp read it there.
// assimp crashes on some damaged files (fuzzing found a .X file that makes its parser follow a
// null pointer), loops or swells on others, and none of that can be caught inside the process
// that reads.
// Decision: the probe is a fresh program, started with posix_spawn, never a fork of the caller.
// A fork copies the caller's memory with every lock another thread held at that moment and no
// thread to release it; the app imports while the scheduler's and OpenMP's threads run, and a
// forked reader once waited for good on the allocator's lock (AddressSanitizer's).
#pragma once

#include <chrono>
#include <cstddef>
#include <string>

namespace ballpit {

// The probe's exit statuses. Anything else (a signal, a sanitizer's exit after a report) is a
// crash.
inline constexpr int kProbeRead = 0;         // assimp read the file
inline constexpr int kProbeUsage = 2;        // the probe was started wrongly
inline constexpr int kProbeRefused = 3;      // assimp refused it cleanly; its message is on stdout
inline constexpr int kProbeOutOfMemory = 4;  // assimp wanted more memory than the probe may have

// How the probe is run: the build's own program unless a test names another, and how long it
// may read and in how much memory. Four seconds is forty times what the Wuson takes (about
// 0.1 s, with or without AddressSanitizer); a probe still reading then is stuck or lost in a
// damaged file, and the import would be too. A minute was too long: fuzzing found a 2.8 KB .X
// file (tests/fuzz_regressions/model_import/slow_8gb_skin_weights.x) that assimp reads for
// 23 s, growing to 8.4 GB, before refusing it. The limit is under half of the fuzzer's 10 s per
// input, which a refusal must fit. The memory limit caps the probe's address space, libraries
// included: the Wuson's probe fits in 32 MB (not in 24), and a file that needs thirty times that
// is damaged or too large to animate. The file above, which grew to 1.5 GB within the time
// limit, is refused at 1 GB in under a second. Sanitizer builds, whose shadow memory is address
// space, run without the cap.
struct ProbeSettings {
  std::string program;  // empty: probe_program()
  std::chrono::milliseconds time_limit{4'000};
  std::size_t memory_limit_mb = 1024;
};

// The probe that runs where ProbeSettings names none: the one set last, else this build's
// ballpit-model-probe (its path is compiled in). An installed library sets the installed probe
// (ballpit::Simulation does, from the CMake package; api/ballpit.h), since the build's may be
// gone. Thread-safe; an empty program restores the build's.
void set_probe_program(const std::string& program);
std::string probe_program();

// Throws ballpit::Error for a model file it refuses: "model file 'PATH': WHAT". The importer
// and the probe word every refusal so.
[[noreturn]] void fail_model_file(const std::string& path, const std::string& what);

// In the importing process: runs the probe on `path` with assimp's post-processing `flags` and
// returns if assimp read the file there. Throws ballpit::Error naming the file if assimp refused
// it (with assimp's message, so the file is read once, not again to learn why), crashed on it,
// did not finish within the time limit or wanted more than the memory limit, or if the probe
// program is missing.
void refuse_unless_assimp_reads_it(const std::string& path, unsigned flags, const ProbeSettings& probe = {});

// Whether the probe caps its memory in this build.
bool probe_limits_memory();

// In the probe process: caps the process's address space at `megabytes` (not in sanitizer
// builds), and makes running out of it exit with kProbeOutOfMemory.
void limit_probe_memory(std::size_t megabytes);

// In the probe process: assimp reads the file; returns the exit status for it, with assimp's
// message written to stdout if it refused the file.
int read_in_probe(const char* path, unsigned flags);

}  // namespace ballpit
