// What every fuzz target in this folder shares: the libFuzzer entry point it defines, and the
// helpers that feed its bytes to the engine the way a user's file would reach it.
// Decision: each target calls the engine's real file entry point (load_scene, load_snapshot,
// import_model) through a temporary file, so the fuzzer tests exactly what `ballpit run`
// reads, error conversion included. A target catches ballpit::Error only, the documented clean
// failure: any other exception, a crash, a hang or a sanitizer report is a finding.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

// Defined once per target (scene_file_target.cpp, ...); called by libFuzzer, or by
// replay_main.cpp for the regression inputs in the normal build.
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace ballpit::fuzz {

// One file per process, rewritten by each input and removed at exit. Its name holds the
// process id, so parallel fuzzing jobs never share it; it lives in $TMPDIR (scripts/fuzz.sh
// points that into build-fuzz/, where a crash's leftover file does no harm).
class TempFile {
 public:
  explicit TempFile(std::string_view suffix);
  ~TempFile();
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;

  // Replaces the file's contents; aborts if it cannot (that is the harness failing, not a finding).
  void write(std::string_view bytes) const;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

}  // namespace ballpit::fuzz
