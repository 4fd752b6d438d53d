// Fuzz target: snapshot files (engine/snapshot.h), read through load_snapshot as
// `ballpit run --load FILE` does, then stepped when small (fuzz/step_world.h).
// Decision: the payload's checksum would turn almost every mutation into "corrupted", so the
// input is tried twice: as it is (the header checks), and with the header's payload size and
// checksum made to match its payload (the field-by-field decoder and the restore checks).
#include <string>

#include "engine/error.h"
#include "engine/snapshot.h"
#include "engine/snapshot_io.h"
#include "engine/world.h"
#include "fuzz/fuzz_target.h"
#include "fuzz/step_world.h"

namespace {

void load_and_step(const ballpit::fuzz::TempFile& file, std::string_view bytes) {
  file.write(bytes);
  try {
    ballpit::World world;
    ballpit::load_snapshot(world, file.path());
    ballpit::fuzz::step_small_world(world, 2);
  } catch (const ballpit::Error&) {
    // The documented clean failure: the file and what is wrong with it.
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const ballpit::fuzz::TempFile file(".snap");
  const std::string_view in = ballpit::fuzz::as_text(data, size);
  load_and_step(file, in);
  if (in.size() >= ballpit::snapshot_io::kHeaderBytes) {
    std::string fixed(in);
    ballpit::snapshot_io::reseal_header(fixed);
    if (fixed != in) load_and_step(file, fixed);
  }
  return 0;
}
