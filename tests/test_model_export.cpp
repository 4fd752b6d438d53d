// Model export to glTF: a model written by export_model_gltf and read back by import_model is
// the same model: joints and hierarchy, bind pose, clips and durations, the skinned vertices of
// every clip at several times, and the vertex colours' bytes. Checked for the marine (made in
// code, with colours) and the Wuson (imported from an X file, without). A failed write throws
// naming the path and leaves no file.
// What is compared: assimp may join identical vertices at import, so vertices are matched, not
// indexed: every vertex of the original must have a vertex in the round trip with the same bind
// position, normal, colour and texture coordinates whose skinned positions agree at every
// sampled time, and every round-trip vertex must be such a match of some original one. Bones
// are matched by joint name, joints by name, clips by name.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "engine/error.h"
#include "engine/marine/marine.h"
#include "engine/model_export.h"
#include "engine/model_import.h"
#include "systems/clip_sampling.h"
#include "systems/skinning.h"

namespace ballpit {
namespace {

// glTF stores floats: positions, matrices and keys survive to float rounding of one or two
// multiplications (1e-7 relative); these bounds leave room for the model units (the Wuson is
// 4 units long) and for the slerp between keys.
constexpr float kBindTolerance = 1e-5f;      // bind positions and rest translations (unit: model units)
constexpr float kMatrixTolerance = 1e-5f;    // entries of rest and inverse bind matrices
constexpr float kSkinnedTolerance = 1e-4f;   // skinned positions (unit: model units; the brief's 1e-4 m)
constexpr float kDurationTolerance = 1e-4f;  // (unit: s)
constexpr float kNormalDot = 0.9999f;        // normals within 0.8 degrees
constexpr float kUvTolerance = 1e-6f;        // texture coordinates, flipped (1 - v) twice

// Debian's assimp-testmodels package installs it here (engine/model_import.h).
constexpr const char* kWusonPath = "/usr/share/assimp/models/X/Testwuson.X";

class TempDir {
 public:
  TempDir() {
    path_ = std::filesystem::temp_directory_path() /
            ("ballpit_export_" + std::to_string(::getpid()) + "_" + std::to_string(counter_++));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  static inline int counter_ = 0;
  std::filesystem::path path_;
};

std::shared_ptr<const Model> round_trip(const Model& model, const std::string& name) {
  static TempDir dir;
  const std::string path = dir.file(name);
  export_model_gltf(model, path);
  return import_model(path);
}

Mat4 local_matrix(const Skeleton& s, std::size_t j) {
  Affine3 a = Affine3::Identity();
  a.translate(s.rest_translation[j]);
  a.rotate(s.rest_rotation[j]);
  a.scale(s.rest_scale[j]);
  return a.matrix();
}

std::string parent_name(const Skeleton& s, std::size_t j) {
  return s.parents[j] < 0 ? std::string("(root)") : s.names[static_cast<std::size_t>(s.parents[j])];
}

// The same joints with the same parents and rest transforms. The export may add one root node
// above the root joints (model_export.h), which import reads as one more joint: it must then be
// b's only root, at identity, and the parent of a's roots.
void expect_same_skeleton(const Model& a, const Model& b) {
  std::string added_root = "(root)";
  if (b.skeleton.size() == a.skeleton.size() + 1) {
    ASSERT_EQ(std::count(b.skeleton.parents.begin(), b.skeleton.parents.end(), -1), 1);
    ASSERT_EQ(b.skeleton.parents[0], -1);
    added_root = b.skeleton.names[0];
    EXPECT_LT(a.skeleton.find(added_root), 0) << added_root;
    EXPECT_TRUE(local_matrix(b.skeleton, 0).isIdentity(kMatrixTolerance));
    EXPECT_EQ(b.skeleton.is_bone[0], 0);
  } else {
    ASSERT_EQ(a.skeleton.size(), b.skeleton.size());
  }
  for (std::size_t j = 0; j < a.skeleton.size(); ++j) {
    const std::string& name = a.skeleton.names[j];
    const int k = b.skeleton.find(name);
    ASSERT_GE(k, 0) << name;
    const std::size_t kb = static_cast<std::size_t>(k);
    const std::string parent = a.skeleton.parents[j] < 0 ? added_root : parent_name(a.skeleton, j);
    EXPECT_EQ(parent, parent_name(b.skeleton, kb)) << name;
    EXPECT_EQ(a.skeleton.is_bone[j], b.skeleton.is_bone[kb]) << name;
    EXPECT_TRUE(local_matrix(a.skeleton, j).isApprox(local_matrix(b.skeleton, kb), kMatrixTolerance) ||
                (local_matrix(a.skeleton, j) - local_matrix(b.skeleton, kb)).cwiseAbs().maxCoeff() < kMatrixTolerance)
        << name << " rest transform";
  }
}

// The inverse bind matrix of every bone, found by its joint's name.
void expect_same_bind(const Model& a, const Model& b) {
  ASSERT_EQ(a.meshes.size(), b.meshes.size());
  for (std::size_t m = 0; m < a.meshes.size(); ++m) {
    const SkinnedMesh& ma = a.meshes[m];
    const SkinnedMesh& mb = b.meshes[m];
    EXPECT_EQ(ma.name, mb.name);
    for (std::size_t i = 0; i < ma.bone_joint.size(); ++i) {
      const std::string& name = a.skeleton.names[ma.bone_joint[i]];
      auto it = std::find_if(mb.bone_joint.begin(), mb.bone_joint.end(),
                             [&](std::uint16_t j) { return b.skeleton.names[j] == name; });
      ASSERT_NE(it, mb.bone_joint.end()) << name;
      const Mat4& ia = ma.inverse_bind[i].matrix();
      const Mat4& ib = mb.inverse_bind[static_cast<std::size_t>(it - mb.bone_joint.begin())].matrix();
      EXPECT_LT((ia - ib).cwiseAbs().maxCoeff(), kMatrixTolerance) << name;
    }
    EXPECT_TRUE(ma.base_color.isApprox(mb.base_color, 1e-6f)) << ma.name;
  }
}

// Skinned positions of every vertex of mesh m at each time of the named clip (the model sits at
// the origin), appended time after time.
std::vector<std::vector<Vec3>> skinned(const Model& model, std::size_t m, const Clip& clip, bool looping,
                                       const std::vector<float>& times) {
  Clip c = clip;
  c.looping = looping;
  std::vector<std::vector<Vec3>> out;
  ClipCursor cursor;
  cursor.reset(model.skeleton.size());
  LocalPose local;
  std::vector<Affine3> joints;
  std::vector<Mat4> palette;
  for (float t : times) {
    sample_clip(c, t, cursor, local);
    local_to_model(model.skeleton, local, joints);
    skinning_palette(model.meshes[m], joints, Affine3::Identity(), palette);
    std::vector<Vec3> positions;
    skin_positions(model.meshes[m], palette, positions);
    out.push_back(std::move(positions));
  }
  return out;
}

// Clips by name with their durations, then the skinned vertices matched as the file comment says.
void expect_same_motion(const Model& a, const Model& b) {
  ASSERT_EQ(a.clips.size(), b.clips.size());
  for (const Clip& ca : a.clips) {
    SCOPED_TRACE(ca.name);
    const Clip& cb = b.clips[b.clip_index(ca.name)];
    EXPECT_NEAR(ca.duration, cb.duration, kDurationTolerance);
    // Key times, between keys, and near the end, where a clip's seam or last key decides.
    std::vector<float> times = {0.0f};
    for (float f : {0.13f, 0.5f, 0.77f, 0.97f}) times.push_back(f * ca.duration);
    for (std::size_t m = 0; m < a.meshes.size(); ++m) {
      const SkinnedMesh& ma = a.meshes[m];
      const SkinnedMesh& mb = b.meshes[m];
      // glTF has no looping flag: the round trip plays the clip as the original does.
      const auto pa = skinned(a, m, ca, ca.looping, times);
      const auto pb = skinned(b, m, cb, ca.looping, times);
      // Round-trip vertices sorted by bind x, so candidates are a narrow window.
      std::vector<std::size_t> order(mb.positions.size());
      for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
      std::sort(order.begin(), order.end(),
                [&](std::size_t x, std::size_t y) { return mb.positions[x].x() < mb.positions[y].x(); });
      std::vector<char> matched(mb.positions.size(), 0);
      std::size_t unmatched = 0;
      float worst = 0.0f;
      for (std::size_t v = 0; v < ma.positions.size(); ++v) {
        const Vec3& p = ma.positions[v];
        auto lo = std::lower_bound(order.begin(), order.end(), p.x() - kBindTolerance,
                                   [&](std::size_t i, float x) { return mb.positions[i].x() < x; });
        bool found = false;
        for (auto it = lo; it != order.end() && mb.positions[*it].x() <= p.x() + kBindTolerance; ++it) {
          const std::size_t w = *it;
          if ((mb.positions[w] - p).cwiseAbs().maxCoeff() > kBindTolerance) continue;
          if (ma.normals[v].dot(mb.normals[w]) < kNormalDot) continue;
          if (ma.colors.empty() != mb.colors.empty()) continue;
          if (!ma.colors.empty() && ma.colors[v] != mb.colors[w]) continue;
          if (ma.uvs.empty() != mb.uvs.empty()) continue;
          if (!ma.uvs.empty() && (ma.uvs[v] - mb.uvs[w]).cwiseAbs().maxCoeff() > kUvTolerance) continue;
          float error = 0.0f;
          for (std::size_t t = 0; t < times.size(); ++t) error = std::max(error, (pa[t][v] - pb[t][w]).norm());
          if (error > kSkinnedTolerance) continue;
          found = true;
          matched[w] = 1;
          worst = std::max(worst, error);
          break;
        }
        if (!found) ++unmatched;
      }
      EXPECT_EQ(unmatched, 0u) << "of " << ma.positions.size() << " vertices of mesh '" << ma.name << "'";
      EXPECT_EQ(std::count(matched.begin(), matched.end(), 0), 0)
          << "round-trip vertices that match none, of " << mb.positions.size() << " (the original has "
          << ma.positions.size() << ")";
      EXPECT_LE(worst, kSkinnedTolerance);
    }
  }
}

TEST(ModelExport, MarineRoundTripKeepsSkeletonBindPoseClipsSkinnedVerticesAndColours) {
  const Model marine = marine::make_marine();
  const auto back = round_trip(marine, "marine.glb");
  expect_same_skeleton(marine, *back);
  expect_same_bind(marine, *back);
  expect_same_motion(marine, *back);
  // A second round trip adds no second root: it is the first one exactly.
  const auto again = round_trip(*back, "marine_again.glb");
  EXPECT_EQ(again->skeleton.size(), back->skeleton.size());
  expect_same_skeleton(*back, *again);
  ASSERT_EQ(back->meshes.size(), marine.meshes.size());
  for (std::size_t m = 0; m < marine.meshes.size(); ++m) {
    EXPECT_EQ(marine.meshes[m].colors.empty(), back->meshes[m].colors.empty());
    EXPECT_EQ(marine.meshes[m].uvs.empty(), back->meshes[m].uvs.empty());
  }
}

TEST(ModelExport, WusonRoundTripKeepsSkeletonBindPoseClipsAndSkinnedVertices) {
  const auto wuson = import_model(kWusonPath);
  // Its look is none of the file's: no colours, no embedded texture, and the 0.5 grey assimp
  // makes up for a file without materials is not taken as its base colour (so the renderer
  // keeps the engine's brown for it).
  ASSERT_EQ(wuson->meshes.size(), 1u);
  EXPECT_TRUE(wuson->meshes[0].colors.empty());
  EXPECT_EQ(wuson->meshes[0].base_color_texture, nullptr);
  EXPECT_EQ(wuson->meshes[0].base_color, Vec4::Ones());
  const auto back = round_trip(*wuson, "wuson.glb");
  // Its root, "$dummy_root", is a plain node already: no root is added.
  EXPECT_EQ(back->skeleton.size(), wuson->skeleton.size());
  expect_same_skeleton(*wuson, *back);
  expect_same_bind(*wuson, *back);
  expect_same_motion(*wuson, *back);
  ASSERT_EQ(back->meshes.size(), 1u);
  EXPECT_TRUE(back->meshes[0].colors.empty());  // none in the file, none made up
  EXPECT_EQ(back->meshes[0].uvs.size(), back->meshes[0].positions.size());
}

// Every byte value of every channel, through linear floats in the file and back.
TEST(ModelExport, VertexColourBytesSurviveTheLinearEncodingOfGltf) {
  Model marine = marine::make_marine();
  SkinnedMesh& mesh = marine.meshes[0];
  mesh.colors.resize(mesh.positions.size());
  for (std::size_t v = 0; v < mesh.colors.size(); ++v)
    mesh.colors[v] = {static_cast<std::uint8_t>(v % 256), static_cast<std::uint8_t>((v * 7 + 3) % 256),
                      static_cast<std::uint8_t>(255 - v % 256), static_cast<std::uint8_t>((v * 13) % 256)};
  mesh.base_color = Vec4(0.25f, 0.5f, 0.75f, 1.0f);
  const auto back = round_trip(marine, "colours.gltf");
  expect_same_bind(marine, *back);  // base colour too
  expect_same_motion(marine, *back);  // matches vertices by colour bytes too
}

// The marine with texture coordinates from his bind position and a small texture of distinct
// texels (4 x 3, so a row or column flip would show).
Model textured_marine() {
  Model marine = marine::make_marine();
  for (SkinnedMesh& mesh : marine.meshes) {
    mesh.uvs.clear();
    for (const Vec3& p : mesh.positions) mesh.uvs.push_back(Vec2(0.5f + p.x(), 1.0f - p.y() / 2.0f));
    auto texture = std::make_shared<Texture>();
    texture->width = 4;
    texture->height = 3;
    for (int i = 0; i < 4 * 3; ++i)
      for (int c = 0; c < 4; ++c) texture->rgba.push_back(static_cast<std::uint8_t>(i * 20 + c * 60 + 1));
    mesh.base_color_texture = texture;
  }
  return marine;
}

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

TEST(ModelExport, TextureAndCoordinatesSurviveAsAnEmbeddedPng) {
  const Model marine = textured_marine();
  const auto back = round_trip(marine, "textured.glb");
  ASSERT_EQ(back->meshes.size(), marine.meshes.size());
  for (std::size_t m = 0; m < marine.meshes.size(); ++m) {
    const auto& a = marine.meshes[m].base_color_texture;
    const auto& b = back->meshes[m].base_color_texture;
    ASSERT_NE(b, nullptr);
    EXPECT_EQ(b->width, a->width);
    EXPECT_EQ(b->height, a->height);
    EXPECT_EQ(b->rgba, a->rgba);  // PNG is lossless: the same bytes, rows in the same order
  }
  expect_same_motion(marine, *back);  // matches vertices by texture coordinates too
}

// An embedded texture import cannot decode is left out; the model still loads, coordinates and all.
TEST(ModelExport, ATextureThatFailsToDecodeOrIsNotPngIsLeftOut) {
  TempDir dir;
  const std::string path = dir.file("textured.glb");
  export_model_gltf(textured_marine(), path);
  const std::string good = read_bytes(path);
  const std::size_t png = good.find("\x89PNG\r\n\x1a\n");
  ASSERT_NE(png, std::string::npos);

  std::string damaged = good;
  for (std::size_t i = png + 8; i < png + 40; ++i) damaged[i] = 'x';  // the header chunk and on
  write_bytes(dir.file("damaged.glb"), damaged);
  const auto a = import_model(dir.file("damaged.glb"));
  EXPECT_EQ(a->meshes[0].base_color_texture, nullptr);
  EXPECT_FALSE(a->meshes[0].uvs.empty());

  // Same length, so the binary container stays valid: the image now says it is a JPEG.
  std::string jpeg = good;
  const std::size_t mime = jpeg.find("image/png");
  ASSERT_NE(mime, std::string::npos);
  jpeg.replace(mime, 9, "image/jpg");
  write_bytes(dir.file("jpeg.glb"), jpeg);
  const auto b = import_model(dir.file("jpeg.glb"));
  EXPECT_EQ(b->meshes[0].base_color_texture, nullptr);
}

TEST(ModelExport, GltfWithItsBufferBesideItReadsBack) {
  TempDir dir;
  const Model marine = marine::make_marine();
  export_model_gltf(marine, dir.file("m.gltf"));
  EXPECT_TRUE(std::filesystem::is_regular_file(dir.file("m.bin")));
  const auto back = import_model(dir.file("m.gltf"));
  expect_same_skeleton(marine, *back);
}

TEST(ModelExport, WriteIntoAMissingFolderThrowsNamingThePathAndLeavesNoFile) {
  TempDir dir;
  const std::string path = dir.file("no/such/folder/marine.glb");
  try {
    export_model_gltf(marine::make_marine(), path);
    FAIL() << "expected ballpit::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(path));
  EXPECT_FALSE(std::filesystem::exists(dir.file("no")));
}

TEST(ModelExport, AFailedWriteLeavesThePreviousFileUntouched) {
  TempDir dir;
  const std::string path = dir.file("keep.glb");
  { std::ofstream(path) << "previous"; }
  // An extension assimp has no writer for is refused before anything is written.
  EXPECT_THROW(export_model_gltf(marine::make_marine(), dir.file("keep.obj")), Error);
  Model empty;
  EXPECT_THROW(export_model_gltf(empty, path), Error);
  std::ifstream in(path);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text, "previous");
  // No temporary file is left beside it.
  std::size_t files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir.file(""))) files += e.is_regular_file() ? 1 : 0;
  EXPECT_EQ(files, 1u);
}

}  // namespace
}  // namespace ballpit
