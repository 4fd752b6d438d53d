// Model import: the facts of the two models every character test runs on, and a clear
// ballpit::Error (naming the file and what is missing) for every kind of bad model file.
#include <gtest/gtest.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <signal.h>
#include <unistd.h>

#include "engine/error.h"
#include "engine/model_import.h"
#include "engine/model_probe.h"
#include "tests/character_fixture.h"

namespace ballpit {
namespace {

using test::epileptic;
using test::kEpilepticPath;
using test::wuson;

// The X files store key times as integer ticks at 4800 per second: a time in seconds is
// exact to float rounding of the division (relative 1e-7).
constexpr float kTimeTolerance = 1e-6f;  // (unit: s)

const Clip& clip(const Model& m, const std::string& name) { return m.clips[m.clip_index(name)]; }

TEST(ModelImport, WusonHas37BonesThreeClipsAndStands1515UnitsTall) {
  const Model& m = *wuson();
  EXPECT_EQ(m.skeleton.bone_count(), 37u);
  // Joints are the bones plus their ancestors that weight no vertex ("Root", "$dummy_root").
  EXPECT_EQ(m.skeleton.size(), 39u);
  EXPECT_GE(m.skeleton.find("Root"), 0);
  ASSERT_EQ(m.clips.size(), 3u);
  EXPECT_NEAR(clip(m, "Wuson_Walk").duration, 17280.0f / 4800.0f, kTimeTolerance);  // 3.6 s
  EXPECT_NEAR(clip(m, "Wuson_Run").duration, 4640.0f / 4800.0f, kTimeTolerance);    // 0.97 s
  EXPECT_EQ(clip(m, "Wuson_Bind").duration, 0.0f);                                  // one pose
  for (const Clip& c : m.clips) {
    EXPECT_EQ(c.ticks_per_second, 4800.0f) << c.name;
    EXPECT_TRUE(c.looping) << c.name;
    EXPECT_EQ(c.tracks.size(), m.skeleton.size()) << c.name;
  }
  // 1.515 units tall (y up), bind-pose vertices from -0.001 to 1.515.
  EXPECT_NEAR(m.bind_height(), 1.515f, 1e-3f);
  // Facing +z: the mouth is at the +z end, the tail tip at the -z end.
  EXPECT_GT(m.bind_max.z() - m.bind_min.z(), 3.0f);
  ASSERT_EQ(m.meshes.size(), 1u);
  EXPECT_EQ(m.meshes[0].bone_joint.size(), 37u);
}

TEST(ModelImport, EpilepticHas54BonesInThreeMeshesAndOne3_3SecondClip) {
  const Model& m = *epileptic();
  EXPECT_EQ(m.skeleton.bone_count(), 54u);
  ASSERT_EQ(m.meshes.size(), 3u);
  EXPECT_EQ(m.meshes[0].name, "Torso");
  EXPECT_EQ(m.meshes[1].name, "Head");
  EXPECT_EQ(m.meshes[2].name, "Legs");
  ASSERT_EQ(m.clips.size(), 1u);
  EXPECT_EQ(m.clips[0].name, "Epileptisch");
  EXPECT_NEAR(m.clips[0].duration, 3.3f, kTimeTolerance);
  // A humanoid about 1.81 units tall: toes at -1.024, top of the head at 0.790.
  EXPECT_NEAR(m.bind_height(), 1.814f, 2e-3f);
}

TEST(ModelImport, EveryVertexHasAtMostFourWeightsSummingToOne) {
  // Normalised in float: a sum of four floats is within a few ulps of 1.
  constexpr float kSumTolerance = 1e-6f;
  for (const Model* m : {wuson().get(), epileptic().get()}) {
    int most = 0;
    for (const SkinnedMesh& mesh : m->meshes) {
      ASSERT_EQ(mesh.bones.size(), mesh.positions.size());
      ASSERT_EQ(mesh.bone_joint.size(), mesh.inverse_bind.size());
      for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
        float sum = 0.0f;
        int used = 0;
        for (int k = 0; k < kMaxInfluences; ++k) {
          EXPECT_GE(mesh.weights[v][k], 0.0f);
          if (mesh.weights[v][k] > 0.0f) ++used;
          sum += mesh.weights[v][k];
          EXPECT_LT(mesh.bones[v][k], mesh.bone_joint.size());
          if (k > 0) {
            EXPECT_LE(mesh.weights[v][k], mesh.weights[v][k - 1]);  // largest first
          }
        }
        most = std::max(most, used);
        EXPECT_NEAR(sum, 1.0f, kSumTolerance) << m->path << " mesh " << mesh.name << " vertex " << v;
      }
    }
    EXPECT_LE(most, kMaxInfluences);
    if (m == wuson().get()) {
      EXPECT_EQ(most, 4);  // the issue: "up to 4 weights per vertex"
    }
  }
}

TEST(ModelImport, ParentsComeBeforeTheirChildren) {
  for (const Model* m : {wuson().get(), epileptic().get()}) {
    const Skeleton& sk = m->skeleton;
    ASSERT_GT(sk.size(), 0u);
    EXPECT_EQ(sk.parents[0], -1);
    for (std::size_t j = 1; j < sk.size(); ++j) {
      EXPECT_GE(sk.parents[j], 0) << sk.names[j];
      EXPECT_LT(sk.parents[j], static_cast<int>(j)) << sk.names[j];
    }
  }
}

TEST(ModelImport, KeysKeepTheirOwnTimesInSeconds) {
  const Model& m = *wuson();
  const Clip& walk = clip(m, "Wuson_Walk");
  // HindLeg_L_01 is keyed every 160 ticks (1/30 s) over the whole 17280-tick clip.
  const JointTrack& hip = walk.tracks[static_cast<std::size_t>(m.skeleton.find("HindLeg_L_01"))];
  ASSERT_EQ(hip.rotation_times.size(), 109u);
  for (std::size_t k = 0; k < hip.rotation_times.size(); ++k)
    EXPECT_NEAR(hip.rotation_times[k], static_cast<float>(k) * 160.0f / 4800.0f, kTimeTolerance);
  // ForeLeg_L_03 skips keys: its second rotation key is at tick 800, not 160.
  const JointTrack& knee = walk.tracks[static_cast<std::size_t>(m.skeleton.find("ForeLeg_L_03"))];
  ASSERT_GE(knee.rotation_times.size(), 2u);
  EXPECT_NEAR(knee.rotation_times[1], 800.0f / 4800.0f, kTimeTolerance);
  // The run moves its root up and down (30 translation keys); the walk does not.
  const std::size_t root = static_cast<std::size_t>(m.skeleton.find("Root"));
  EXPECT_EQ(clip(m, "Wuson_Run").tracks[root].translations.size(), 30u);
  EXPECT_EQ(walk.tracks[root].translations.size(), 1u);
}

TEST(ModelImport, AJointNoClipAnimatesHoldsItsRestPose) {
  // The Wuson's clips key every node but assimp's "$dummy_root" (the file's unnamed top).
  const Model& m = *wuson();
  const int top = m.skeleton.find("$dummy_root");
  ASSERT_EQ(top, 0);
  for (const Clip& c : m.clips) {
    const JointTrack& t = c.tracks[0];
    ASSERT_EQ(t.rotations.size(), 1u) << c.name;
    EXPECT_TRUE(t.rotations[0].coeffs() == m.skeleton.rest_rotation[0].coeffs()) << c.name;
    EXPECT_TRUE(t.translations[0] == m.skeleton.rest_translation[0]) << c.name;
  }
}

// import_model reads the file in a separate process first (engine/model_import.cpp). That
// process must start afresh: a fork of this one inherits every lock another thread held at that
// moment, with no thread left to release it. It once waited for good on the allocator's lock
// under AddressSanitizer: the app imports while the scheduler's and OpenMP's threads run. Here a
// thread allocates without pause through ten imports.
TEST(ModelImport, ImportsFinishWhileAnotherThreadAllocates) {
  std::atomic<bool> stop{false};
  std::thread churn([&] {
    std::vector<std::unique_ptr<char[]>> held(64);
    for (std::size_t i = 0; !stop.load(std::memory_order_relaxed); ++i)
      held[i % held.size()] = std::make_unique<char[]>(16 + i % 4096);
  });
  for (int i = 0; i < 10; ++i) EXPECT_NO_THROW(import_model(kWusonModelPath)) << "import " << i;
  stop = true;
  churn.join();
}

// ---- bad files: each error names the file and what is missing; none crashes ----------------

struct TempDir {
  std::filesystem::path path;
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path = std::filesystem::temp_directory_path() /
           ("ballpit_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    std::filesystem::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
};

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// Imports `path` expecting ballpit::Error; returns its message.
std::string import_error(const std::string& path) {
  try {
    import_model(path);
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "no error importing " << path;
  return {};
}

TEST(ModelImportErrors, AMissingFileNamesThePath) {
  TempDir dir;
  const std::string path = (dir.path / "no_such_model.X").string();
  const std::string msg = import_error(path);
  EXPECT_NE(msg.find(path), std::string::npos) << msg;
  EXPECT_NE(msg.find("cannot open"), std::string::npos) << msg;
}

TEST(ModelImportErrors, ATruncatedFileIsRejected) {
  TempDir dir;
  const std::string whole = read_all(kWusonModelPath);
  ASSERT_GT(whole.size(), 100000u);
  // Cut in the middle of the mesh, and again just before the end.
  for (std::size_t keep : {whole.size() / 3, whole.size() - 600}) {
    const std::filesystem::path path = dir.path / ("truncated_" + std::to_string(keep) + ".X");
    write(path, whole.substr(0, keep));
    const std::string msg = import_error(path.string());
    EXPECT_NE(msg.find(path.string()), std::string::npos) << msg;
    EXPECT_NE(msg.find("cannot read"), std::string::npos) << msg;
  }
}

// Debian's assimp keeps its internal assertions, which abort the process; this fuzz-found .X
// file fails one in the triangulation. It must be refused like any other bad file.
TEST(ModelImportErrors, AFileFailingAnAssimpInternalCheckIsRefusedNotFatal) {
  const std::string path = std::string(BALLPIT_SOURCE_DIR) + "/tests/fuzz_regressions/model_import/triangulation_count_assert.x";
  const std::string msg = import_error(path);
  EXPECT_NE(msg.find(path), std::string::npos) << msg;
  EXPECT_NE(msg.find("assimp cannot read it: an internal check failed"), std::string::npos) << msg;
}

// And this one makes assimp's .X parser follow a null pointer: caught by reading it in a child
// process first.
TEST(ModelImportErrors, AFileThatCrashesAssimpIsRefusedNotFatal) {
  const std::string path = std::string(BALLPIT_SOURCE_DIR) + "/tests/fuzz_regressions/model_import/null_pointer_in_x_parser.x";
  const std::string msg = import_error(path);
  EXPECT_NE(msg.find(path), std::string::npos) << msg;
  // "(Segmentation fault)"; under AddressSanitizer, which ends the child itself, "(exit status 1)".
  EXPECT_NE(msg.find("assimp crashed reading it ("), std::string::npos) << msg;
  EXPECT_NE(msg.find("): the file is damaged"), std::string::npos) << msg;
}

// The probe's deadline, tried with a stand-in probe that never finishes: a script that notes its
// process id and sleeps.
TEST(ModelImportErrors, AProbeStillReadingAtItsTimeLimitIsKilledAndTheFileRefused) {
  TempDir dir;
  const std::filesystem::path pid_file = dir.path / "pid", stuck = dir.path / "stuck_probe.sh";
  write(stuck, "#!/bin/sh\necho $$ > '" + pid_file.string() + "'\nexec sleep 30\n");
  std::filesystem::permissions(stuck, std::filesystem::perms::owner_all);
  try {
    refuse_unless_assimp_reads_it(kWusonModelPath, 0, {stuck.string(), std::chrono::milliseconds(300)});
    FAIL() << "no error for a probe that never finishes";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(kWusonModelPath), std::string::npos) << msg;
    EXPECT_NE(msg.find("did not finish reading it within 0.3 s"), std::string::npos) << msg;
  }
  // Killed and reaped, not left sleeping.
  const pid_t pid = std::stoi(read_all(pid_file.string()));
  EXPECT_EQ(kill(pid, 0), -1);
  EXPECT_EQ(errno, ESRCH);
}

// A refusal is reported with the message the probe got from assimp, so the importer need not
// read the file again to learn it: a stand-in probe refuses the good Wuson with its own reason,
// and that reason, not a successful read, is what the caller gets.
TEST(ModelImportErrors, ARefusalCarriesTheProbesMessageAndTheFileIsNotReadAgain) {
  TempDir dir;
  const std::filesystem::path refusing = dir.path / "refusing_probe.sh";
  write(refusing, "#!/bin/sh\nprintf 'the stand-in refused it'\nexit " + std::to_string(kProbeRefused) + "\n");
  std::filesystem::permissions(refusing, std::filesystem::perms::owner_all);
  try {
    refuse_unless_assimp_reads_it(kWusonModelPath, 0, {refusing.string()});
    FAIL() << "no error for a refused file";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(std::string(kWusonModelPath) + "': assimp cannot read it: the stand-in refused it"), std::string::npos)
        << msg;
  }
}

// The probe's address space is capped: this fuzz-found file makes assimp grow to 8.4 GB before
// it refuses it. Under a 256 MB cap the real probe gives up within a second or so instead of
// swelling until the time limit.
TEST(ModelImportErrors, AFileThatSwellsAssimpPastTheProbesMemoryLimitIsRefused) {
  if (!probe_limits_memory()) GTEST_SKIP() << "sanitizer build: the probe runs without a memory limit";
  const std::string path = std::string(BALLPIT_SOURCE_DIR) + "/tests/fuzz_regressions/model_import/slow_8gb_skin_weights.x";
  ProbeSettings probe;
  probe.memory_limit_mb = 256;
  try {
    refuse_unless_assimp_reads_it(path, 0, probe);
    FAIL() << "no error for a file that needs gigabytes";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(path + "': assimp needed more than 256 MB to read it"), std::string::npos) << msg;
  }
  // The Wuson reads within the same cap.
  EXPECT_NO_THROW(refuse_unless_assimp_reads_it(kWusonModelPath, 0, probe));
}

TEST(ModelImportErrors, AMissingProbeIsAnErrorThatNamesIt) {
  const std::string missing = "/nonexistent/ballpit-model-probe";
  try {
    refuse_unless_assimp_reads_it(kWusonModelPath, 0, {missing});
    FAIL() << "no error for a missing probe";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("the model probe '" + missing + "' is missing"), std::string::npos) << msg;
  }
}

TEST(ModelImportErrors, AMeshWithoutBonesHasNoSkeleton) {
  TempDir dir;
  const std::filesystem::path path = dir.path / "triangle.obj";
  write(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const std::string msg = import_error(path.string());
  EXPECT_NE(msg.find(path.string()), std::string::npos) << msg;
  EXPECT_NE(msg.find("no skeleton"), std::string::npos) << msg;
}

TEST(ModelImportErrors, AModelWithoutAnimationsHasNoClips) {
  TempDir dir;
  // The Wuson up to its first AnimationSet: skeleton and skinned mesh, complete, no clips.
  const std::string whole = read_all(kWusonModelPath);
  const std::size_t cut = whole.find("AnimationSet Wuson_Run");
  ASSERT_NE(cut, std::string::npos);
  const std::filesystem::path path = dir.path / "no_clips.X";
  write(path, whole.substr(0, cut));
  const std::string msg = import_error(path.string());
  EXPECT_NE(msg.find(path.string()), std::string::npos) << msg;
  EXPECT_NE(msg.find("no animation clips"), std::string::npos) << msg;
}

TEST(ModelImportErrors, AnUnknownClipNameListsTheClipsThereAre) {
  try {
    wuson()->clip_index("Wuson_Dance");
    FAIL() << "no error for an unknown clip";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(kWusonModelPath), std::string::npos) << msg;
    EXPECT_NE(msg.find("'Wuson_Dance'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("'Wuson_Walk'"), std::string::npos) << msg;
  }
  // The same through a character: the scene names clips by name.
  World world;
  CharacterDesc desc = CharacterDesc::wuson();
  desc.run_clip = "Wuson_Gallop";
  try {
    add_character(world, wuson(), desc);
    FAIL() << "no error for an unknown run clip";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("'Wuson_Gallop'"), std::string::npos) << e.what();
  }
  EXPECT_EQ(world.characters.size(), 0u);
  EXPECT_EQ(world.colliders.size(), 0u);
}

TEST(ModelImportErrors, ADirectoryIsNotAModel) {
  TempDir dir;
  const std::string msg = import_error(dir.path.string());
  EXPECT_NE(msg.find("directory"), std::string::npos) << msg;
}

TEST(ModelImportErrors, AClipThatDoesNotWalkCannotPlayWalk) {
  // The humanoid's one clip is a fit, not a walk cycle: it cannot drive locomotion.
  World world;
  CharacterDesc desc = CharacterDesc::wuson();
  desc.model_path = kEpilepticPath;
  desc.idle_clip = desc.walk_clip = desc.run_clip = "Epileptisch";
  try {
    add_character(world, epileptic(), desc);
    FAIL() << "no error for a walk clip that does not walk";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(kEpilepticPath), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("'Epileptisch' is not a locomotion cycle"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace ballpit
