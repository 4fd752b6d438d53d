#include "engine/model_import.h"

#include <assimp/Importer.hpp>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <png.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include "engine/clip_sources.h"
#include "engine/marine/marine.h"
#include "engine/model_probe.h"
#include "engine/srgb.h"

namespace ballpit {

namespace {

// assimp's own convention for files that leave the time base unset.
constexpr double kDefaultTicksPerSecond = 25.0;

// A weight below this is dropped before normalising: the file's rounding noise, far below any
// visible influence (1e-6 of a vertex's total).
constexpr float kNegligibleWeight = 1e-6f;

Affine3 to_affine(const aiMatrix4x4& m) {
  Mat4 out;
  out << m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4, m.d1, m.d2, m.d3, m.d4;
  return Affine3(out);
}

Quat to_quat(const aiQuaternion& q) { return Quat(q.w, q.x, q.y, q.z).normalized(); }
Vec3 to_vec(const aiVector3D& v) { return Vec3(v.x, v.y, v.z); }

// Preorder walk: a node is a joint if it is a bone or an ancestor of one. Returns whether the
// subtree holds a bone.
bool has_bone(const aiNode* node, const std::unordered_set<std::string>& bones,
              std::unordered_map<const aiNode*, bool>& memo) {
  bool any = bones.count(node->mName.C_Str()) > 0;
  for (unsigned i = 0; i < node->mNumChildren; ++i) any = has_bone(node->mChildren[i], bones, memo) || any;
  memo[node] = any;
  return any;
}

void add_joints(const aiNode* node, int parent, const std::unordered_set<std::string>& bones,
                const std::unordered_map<const aiNode*, bool>& memo, Skeleton& sk) {
  if (!memo.at(node)) return;
  int self = static_cast<int>(sk.size());
  aiVector3D scale, position;
  aiQuaternion rotation;
  node->mTransformation.Decompose(scale, rotation, position);
  sk.names.emplace_back(node->mName.C_Str());
  sk.parents.push_back(parent);
  sk.rest_translation.push_back(to_vec(position));
  sk.rest_rotation.push_back(to_quat(rotation));
  sk.rest_scale.push_back(to_vec(scale));
  sk.is_bone.push_back(bones.count(node->mName.C_Str()) ? 1 : 0);
  for (unsigned i = 0; i < node->mNumChildren; ++i) add_joints(node->mChildren[i], self, bones, memo, sk);
}

// A PNG from memory as RGBA8, rows top to bottom; null if libpng refuses it (the texture is then
// left out: a model draws without it rather than not at all).
std::shared_ptr<const Texture> decode_png(const unsigned char* bytes, std::size_t size) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_memory(&image, bytes, size)) return nullptr;
  image.format = PNG_FORMAT_RGBA;
  // Far beyond any texture (16k x 16k); refuses a damaged header's absurd size.
  constexpr png_uint_32 kMaxSide = 16384;
  if (image.width == 0 || image.height == 0 || image.width > kMaxSide || image.height > kMaxSide) {
    png_image_free(&image);
    return nullptr;
  }
  auto texture = std::make_shared<Texture>();
  texture->width = static_cast<int>(image.width);
  texture->height = static_cast<int>(image.height);
  texture->rgba.resize(PNG_IMAGE_SIZE(image));
  if (!png_image_finish_read(&image, nullptr, texture->rgba.data(), 0, nullptr)) {
    png_image_free(&image);
    return nullptr;
  }
  return texture;
}

// The base colour texture of a material when the file embeds it: uncompressed texels as they
// are, a PNG decoded; another format (JPEG, ...), a texture in a file of its own, or one that
// fails to decode is left out without an error.
std::shared_ptr<const Texture> import_texture(const aiScene* scene, const aiMaterial* material) {
  aiString where;
  if (material->GetTexture(aiTextureType_BASE_COLOR, 0, &where) != AI_SUCCESS &&
      material->GetTexture(aiTextureType_DIFFUSE, 0, &where) != AI_SUCCESS)
    return nullptr;
  const aiTexture* t = scene->GetEmbeddedTexture(where.C_Str());
  if (!t || !t->pcData || t->mWidth == 0) return nullptr;
  if (t->mHeight == 0) {  // compressed: mWidth bytes in the format of achFormatHint
    if (!t->CheckFormat("png")) return nullptr;
    return decode_png(reinterpret_cast<const unsigned char*>(t->pcData), t->mWidth);
  }
  auto texture = std::make_shared<Texture>();
  texture->width = static_cast<int>(t->mWidth);
  texture->height = static_cast<int>(t->mHeight);
  const std::size_t texels = std::size_t{t->mWidth} * t->mHeight;
  texture->rgba.resize(texels * 4);
  for (std::size_t i = 0; i < texels; ++i) {
    const aiTexel& x = t->pcData[i];
    texture->rgba[4 * i + 0] = x.r;
    texture->rgba[4 * i + 1] = x.g;
    texture->rgba[4 * i + 2] = x.b;
    texture->rgba[4 * i + 3] = x.a;
  }
  return texture;
}

// How the mesh looks: vertex colours, texture coordinates, and its material's base colour and
// texture. Colours become sRGB bytes: glTF files store linear COLOR_0 (encoded here, the inverse
// of model_export.cpp, so a round trip keeps the bytes); other formats' colours are taken as
// the display values their authoring tools show (already sRGB). Material colours are linear
// factors in every format. Coordinates get v down from the image's top row, glTF's convention
// (assimp's is v up).
void import_look(const aiScene* scene, const aiMesh* m, bool linear_colors, SkinnedMesh& mesh) {
  const unsigned n = m->mNumVertices;
  if (m->mColors[0]) {
    mesh.colors.resize(n);
    for (unsigned v = 0; v < n; ++v) {
      const aiColor4D& c = m->mColors[0][v];
      auto encode = [&](float x) {
        return unit_to_byte(linear_colors ? linear_to_srgb(std::clamp(x, 0.0f, 1.0f)) : x);
      };
      mesh.colors[v] = {encode(c.r), encode(c.g), encode(c.b), unit_to_byte(c.a)};
    }
  }
  if (m->mTextureCoords[0]) {
    mesh.uvs.resize(n);
    for (unsigned v = 0; v < n; ++v) mesh.uvs[v] = Vec2(m->mTextureCoords[0][v].x, 1.0f - m->mTextureCoords[0][v].y);
  }
  if (m->mMaterialIndex >= scene->mNumMaterials) return;
  const aiMaterial* material = scene->mMaterials[m->mMaterialIndex];
  // A material assimp made up for a file that has none has no name (the X importer's 0.5 grey,
  // the Wuson's) or AI_DEFAULT_MATERIAL_NAME: its diffuse colour is not the file's, so ignored.
  aiString name;
  const bool from_file = material->Get(AI_MATKEY_NAME, name) == AI_SUCCESS && name.length > 0 &&
                         std::strcmp(name.C_Str(), AI_DEFAULT_MATERIAL_NAME) != 0;
  aiColor4D base(1.0f, 1.0f, 1.0f, 1.0f);
  if (material->Get(AI_MATKEY_BASE_COLOR, base) == AI_SUCCESS ||
      (from_file && material->Get(AI_MATKEY_COLOR_DIFFUSE, base) == AI_SUCCESS))
    mesh.base_color = Vec4(base.r, base.g, base.b, base.a);
  if (!mesh.uvs.empty()) mesh.base_color_texture = import_texture(scene, material);
}

SkinnedMesh import_mesh(const std::string& path, const aiScene* scene, const aiMesh* m, const Skeleton& sk,
                        bool linear_colors) {
  SkinnedMesh mesh;
  mesh.name = m->mName.C_Str();
  const unsigned n = m->mNumVertices;
  mesh.positions.resize(n);
  mesh.normals.resize(n, Vec3::UnitY());
  for (unsigned v = 0; v < n; ++v) {
    mesh.positions[v] = to_vec(m->mVertices[v]);
    if (m->mNormals) mesh.normals[v] = to_vec(m->mNormals[v]).normalized();
  }
  for (unsigned f = 0; f < m->mNumFaces; ++f) {
    const aiFace& face = m->mFaces[f];
    if (face.mNumIndices != 3) continue;  // points and lines left by the triangulation
    for (int k = 0; k < 3; ++k) mesh.indices.push_back(face.mIndices[k]);
  }

  // Gather every influence, then keep the four largest per vertex and normalise them.
  std::vector<std::vector<std::pair<float, std::uint16_t>>> influences(n);
  for (unsigned b = 0; b < m->mNumBones; ++b) {
    const aiBone* bone = m->mBones[b];
    int joint = sk.find(bone->mName.C_Str());
    if (joint < 0) fail_model_file(path, "bone '" + std::string(bone->mName.C_Str()) + "' of mesh '" + mesh.name + "' has no node");
    mesh.bone_joint.push_back(static_cast<std::uint16_t>(joint));
    mesh.inverse_bind.push_back(to_affine(bone->mOffsetMatrix));
    for (unsigned k = 0; k < bone->mNumWeights; ++k) {
      const aiVertexWeight& w = bone->mWeights[k];
      if (w.mVertexId >= n) fail_model_file(path, "mesh '" + mesh.name + "' weights a vertex it does not have");
      if (w.mWeight > kNegligibleWeight) influences[w.mVertexId].push_back({w.mWeight, static_cast<std::uint16_t>(b)});
    }
  }
  mesh.bones.assign(n, {0, 0, 0, 0});
  mesh.weights.assign(n, {0.0f, 0.0f, 0.0f, 0.0f});
  std::size_t unweighted = 0;
  for (unsigned v = 0; v < n; ++v) {
    auto& list = influences[v];
    if (list.empty()) {
      ++unweighted;
      continue;
    }
    // Largest first; equal weights by bone index, so the choice does not depend on file order.
    std::sort(list.begin(), list.end(), [](const auto& a, const auto& b) {
      return a.first != b.first ? a.first > b.first : a.second < b.second;
    });
    const std::size_t keep = std::min<std::size_t>(list.size(), kMaxInfluences);
    float total = 0.0f;
    for (std::size_t k = 0; k < keep; ++k) total += list[k].first;
    for (std::size_t k = 0; k < keep; ++k) {
      mesh.bones[v][k] = list[k].second;
      mesh.weights[v][k] = list[k].first / total;
    }
  }
  if (unweighted > 0) {
    fail_model_file(path, "mesh '" + mesh.name + "' has " + std::to_string(unweighted) + " of " + std::to_string(n) +
                              " vertices with no bone weight (every vertex of a skinned mesh must follow a bone)");
  }
  import_look(scene, m, linear_colors, mesh);
  return mesh;
}

// Keys with their own times, converted to seconds. A key not later than the one before it
// (files repeat the last key) is dropped so times strictly increase.
template <class Key, class Value, class Convert>
void import_keys(const Key* keys, unsigned count, double tps, std::vector<float>& times,
                 std::vector<Value>& values, Convert convert) {
  times.clear();
  values.clear();
  for (unsigned k = 0; k < count; ++k) {
    float t = static_cast<float>(keys[k].mTime / tps);
    if (!times.empty() && !(t > times.back())) continue;
    times.push_back(t);
    values.push_back(convert(keys[k].mValue));
  }
}

Clip import_clip(const aiAnimation* a, std::size_t index, const Skeleton& sk) {
  Clip clip;
  clip.name = a->mName.length > 0 ? a->mName.C_Str() : "clip" + std::to_string(index);
  const double tps = a->mTicksPerSecond > 0.0 ? a->mTicksPerSecond : kDefaultTicksPerSecond;
  clip.ticks_per_second = static_cast<float>(tps);
  clip.duration = static_cast<float>(a->mDuration / tps);
  rest_tracks(sk, clip);
  for (unsigned c = 0; c < a->mNumChannels; ++c) {
    const aiNodeAnim* ch = a->mChannels[c];
    int j = sk.find(ch->mNodeName.C_Str());
    if (j < 0) continue;  // a mesh node or helper: not part of the skeleton
    JointTrack& t = clip.tracks[static_cast<std::size_t>(j)];
    if (ch->mNumPositionKeys > 0)
      import_keys(ch->mPositionKeys, ch->mNumPositionKeys, tps, t.translation_times, t.translations, to_vec);
    if (ch->mNumRotationKeys > 0)
      import_keys(ch->mRotationKeys, ch->mNumRotationKeys, tps, t.rotation_times, t.rotations, to_quat);
    if (ch->mNumScalingKeys > 0)
      import_keys(ch->mScalingKeys, ch->mNumScalingKeys, tps, t.scale_times, t.scales, to_vec);
  }
  return clip;
}

// The file read by assimp, after the model probe read it safely (engine/model_probe.h).
// `clips_only`: a file of a skeleton and animations, which assimp marks incomplete for having
// no mesh (AI_SCENE_FLAGS_INCOMPLETE: "allows the import of animation skeletons").
const aiScene* read_file(Assimp::Importer& importer, const std::string& path, unsigned flags, bool clips_only = false) {
  {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) fail_model_file(path, "is a directory, not a model file");
    std::ifstream readable(path, std::ios::binary);
    if (!readable) fail_model_file(path, std::string("cannot open it (") + std::strerror(errno) + ")");
  }
  refuse_unless_assimp_reads_it(path, flags);
  const aiScene* scene = importer.ReadFile(path, flags);
  // Where no probe could run (no process to spare), assimp's refusal is learnt here.
  if (!scene) fail_model_file(path, std::string("assimp cannot read it: ") + importer.GetErrorString());
  if ((!clips_only && (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE)) || !scene->mRootNode)
    fail_model_file(path, "assimp read it only partly (the file is incomplete or damaged)");
  return scene;
}

}  // namespace

std::shared_ptr<const Model> import_model(const std::string& path, const ModelImportOptions& options) {
  Assimp::Importer importer;
  // Four influences at most (LimitBoneWeights' default), triangles only, and a structural
  // check so a damaged file is rejected by assimp rather than read half-way.
  const unsigned flags = aiProcess_Triangulate | aiProcess_LimitBoneWeights | aiProcess_JoinIdenticalVertices |
                         aiProcess_GenSmoothNormals | aiProcess_ValidateDataStructure;
  const aiScene* scene = read_file(importer, path, flags);

  std::unordered_set<std::string> bones;
  for (unsigned i = 0; i < scene->mNumMeshes; ++i)
    for (unsigned b = 0; b < scene->mMeshes[i]->mNumBones; ++b) bones.insert(scene->mMeshes[i]->mBones[b]->mName.C_Str());
  if (bones.empty()) {
    fail_model_file(path, "has no skeleton: none of its " + std::to_string(scene->mNumMeshes) +
                              " meshes has bones, so nothing can animate it");
  }
  if (scene->mNumAnimations == 0 && options.require_clips)
    fail_model_file(path, "has no animation clips (a character needs at least one)");

  auto model = std::make_shared<Model>();
  model->path = path;
  std::unordered_map<const aiNode*, bool> memo;
  has_bone(scene->mRootNode, bones, memo);
  add_joints(scene->mRootNode, -1, bones, memo, model->skeleton);
  if (model->skeleton.size() > 0xffff) fail_model_file(path, "has more joints than the engine indexes (65535)");

  // Only meshes with bones are skinned; a mesh without bones belongs to no joint and is left out.
  // glTF's vertex colours are linear; other formats' are taken as sRGB (import_look).
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  const bool linear_colors = extension == ".gltf" || extension == ".glb";
  for (unsigned i = 0; i < scene->mNumMeshes; ++i) {
    const aiMesh* m = scene->mMeshes[i];
    if (m->mNumBones == 0) continue;
    model->meshes.push_back(import_mesh(path, scene, m, model->skeleton, linear_colors));
  }
  model->bind_min = Vec3::Constant(std::numeric_limits<float>::max());
  model->bind_max = Vec3::Constant(-std::numeric_limits<float>::max());
  for (const SkinnedMesh& m : model->meshes)
    for (const Vec3& p : m.positions) {
      model->bind_min = model->bind_min.cwiseMin(p);
      model->bind_max = model->bind_max.cwiseMax(p);
    }
  if (model->vertex_count() == 0) fail_model_file(path, "its skinned meshes have no vertices");

  for (unsigned i = 0; i < scene->mNumAnimations; ++i)
    model->clips.push_back(import_clip(scene->mAnimations[i], i, model->skeleton));
  return model;
}

std::vector<FileClip> import_clips(const std::string& path) {
  Assimp::Importer importer;
  // Only the node tree and the animations are read: no mesh post-processing, since a clip file
  // may have no mesh at all.
  const aiScene* scene = read_file(importer, path, aiProcess_ValidateDataStructure, true);
  if (scene->mNumAnimations == 0) fail_model_file(path, "has no animation clips");
  std::vector<FileClip> clips;
  for (unsigned i = 0; i < scene->mNumAnimations; ++i) {
    const aiAnimation* a = scene->mAnimations[i];
    FileClip clip;
    clip.name = a->mName.length > 0 ? a->mName.C_Str() : "clip" + std::to_string(i);
    const double tps = a->mTicksPerSecond > 0.0 ? a->mTicksPerSecond : kDefaultTicksPerSecond;
    clip.ticks_per_second = static_cast<float>(tps);
    clip.duration = static_cast<float>(a->mDuration / tps);
    for (unsigned c = 0; c < a->mNumChannels; ++c) {
      const aiNodeAnim* ch = a->mChannels[c];
      JointTrack t;
      import_keys(ch->mPositionKeys, ch->mNumPositionKeys, tps, t.translation_times, t.translations, to_vec);
      import_keys(ch->mRotationKeys, ch->mNumRotationKeys, tps, t.rotation_times, t.rotations, to_quat);
      import_keys(ch->mScalingKeys, ch->mNumScalingKeys, tps, t.scale_times, t.scales, to_vec);
      clip.nodes.emplace_back(ch->mNodeName.C_Str());
      clip.tracks.push_back(std::move(t));
    }
    clips.push_back(std::move(clip));
  }
  return clips;
}

bool is_builtin_model(const std::string& path) { return path == marine::kModelName; }

std::shared_ptr<const Model> load_model(const std::string& path) {
  if (path == marine::kModelName) return marine::marine_model();
  if (is_clip_sources_name(path)) return load_clip_sources(path);
  return import_model(path);
}

}  // namespace ballpit
