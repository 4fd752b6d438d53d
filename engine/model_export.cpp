#include "engine/model_export.h"

#include <assimp/Exporter.hpp>
#include <assimp/material.h>
#include <assimp/scene.h>
#include <png.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "engine/atomic_file.h"
#include "engine/error.h"
#include "engine/srgb.h"

namespace ballpit {

namespace {

// The time base the clips' keys are written in (assimp divides it out again: glTF keys are in
// seconds). The engine's clips keep seconds, so any base is exact to float rounding.
constexpr double kExportTicksPerSecond = 1000.0;

[[noreturn]] void fail(const std::string& path, const std::string& why) {
  throw Error("cannot export a model to '" + path + "': " + why);
}

aiVector3D to_ai(const Vec3& v) { return aiVector3D(v.x(), v.y(), v.z()); }
aiQuaternion to_ai(const Quat& q) { return aiQuaternion(q.w(), q.x(), q.y(), q.z()); }

aiMatrix4x4 to_ai(const Affine3& a) {
  const Mat4& m = a.matrix();
  return aiMatrix4x4(m(0, 0), m(0, 1), m(0, 2), m(0, 3), m(1, 0), m(1, 1), m(1, 2), m(1, 3), m(2, 0), m(2, 1),
                     m(2, 2), m(2, 3), m(3, 0), m(3, 1), m(3, 2), m(3, 3));
}

// Children arrays are allocated once their count is known; assimp frees them with delete[].
void set_children(aiNode* node, const std::vector<aiNode*>& children) {
  if (children.empty()) return;
  node->mNumChildren = static_cast<unsigned>(children.size());
  node->mChildren = new aiNode*[children.size()];
  for (std::size_t i = 0; i < children.size(); ++i) {
    node->mChildren[i] = children[i];
    children[i]->mParent = node;
  }
}

aiMesh* export_mesh(const SkinnedMesh& src, const Skeleton& sk, unsigned material) {
  auto* m = new aiMesh;
  m->mName = aiString(src.name);
  m->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
  m->mMaterialIndex = material;
  const std::size_t n = src.positions.size();
  m->mNumVertices = static_cast<unsigned>(n);
  m->mVertices = new aiVector3D[n];
  m->mNormals = new aiVector3D[n];
  for (std::size_t v = 0; v < n; ++v) {
    m->mVertices[v] = to_ai(src.positions[v]);
    m->mNormals[v] = to_ai(v < src.normals.size() ? src.normals[v] : Vec3::UnitY());
  }
  // glTF's COLOR_0 is linear: the sRGB bytes are decoded here and encoded again at import.
  if (src.colors.size() == n) {
    m->mColors[0] = new aiColor4D[n];
    for (std::size_t v = 0; v < n; ++v) {
      const auto& c = src.colors[v];
      m->mColors[0][v] = aiColor4D(srgb_to_linear(byte_to_unit(c[0])), srgb_to_linear(byte_to_unit(c[1])),
                                   srgb_to_linear(byte_to_unit(c[2])), byte_to_unit(c[3]));
    }
  }
  // The engine's coordinates have v down from the image's top row (glTF's own); assimp's
  // have v up, and its glTF exporter flips them back.
  if (src.uvs.size() == n) {
    m->mNumUVComponents[0] = 2;
    m->mTextureCoords[0] = new aiVector3D[n];
    for (std::size_t v = 0; v < n; ++v)
      m->mTextureCoords[0][v] = aiVector3D(src.uvs[v].x(), 1.0f - src.uvs[v].y(), 0.0f);
  }
  const std::size_t faces = src.indices.size() / 3;
  m->mNumFaces = static_cast<unsigned>(faces);
  m->mFaces = new aiFace[faces];
  for (std::size_t f = 0; f < faces; ++f) {
    aiFace& face = m->mFaces[f];
    face.mNumIndices = 3;
    face.mIndices = new unsigned[3];
    for (int k = 0; k < 3; ++k) face.mIndices[k] = src.indices[3 * f + static_cast<std::size_t>(k)];
  }

  // Bones: one per mesh bone, named by its joint (assimp's glTF exporter finds the joint's node
  // by that name), with the weights of the vertices that use it.
  const std::size_t bones = src.bone_joint.size();
  std::vector<std::vector<aiVertexWeight>> weights(bones);
  for (std::size_t v = 0; v < n; ++v)
    for (int k = 0; k < kMaxInfluences; ++k)
      if (src.weights[v][static_cast<std::size_t>(k)] > 0.0f)
        weights[src.bones[v][static_cast<std::size_t>(k)]].push_back(
            aiVertexWeight(static_cast<unsigned>(v), src.weights[v][static_cast<std::size_t>(k)]));
  m->mNumBones = static_cast<unsigned>(bones);
  m->mBones = bones ? new aiBone*[bones] : nullptr;
  for (std::size_t b = 0; b < bones; ++b) {
    auto* bone = new aiBone;
    bone->mName = aiString(sk.names[src.bone_joint[b]]);
    bone->mOffsetMatrix = to_ai(src.inverse_bind[b]);
    bone->mNumWeights = static_cast<unsigned>(weights[b].size());
    bone->mWeights = weights[b].empty() ? nullptr : new aiVertexWeight[weights[b].size()];
    std::copy(weights[b].begin(), weights[b].end(), bone->mWeights);
    m->mBones[b] = bone;
  }
  return m;
}

// The texture as an embedded PNG (assimp frees pcData with delete[] as aiTexel, so the bytes go
// into aiTexels); null if it has no texels or libpng cannot encode it.
aiTexture* export_texture(const Texture& t) {
  if (t.width <= 0 || t.height <= 0 ||
      t.rgba.size() != static_cast<std::size_t>(t.width) * static_cast<std::size_t>(t.height) * 4)
    return nullptr;
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  image.width = static_cast<png_uint_32>(t.width);
  image.height = static_cast<png_uint_32>(t.height);
  image.format = PNG_FORMAT_RGBA;
  png_alloc_size_t size = 0;
  if (!png_image_write_to_memory(&image, nullptr, &size, 0, t.rgba.data(), 0, nullptr) || size == 0) return nullptr;
  std::vector<unsigned char> png(size);
  if (!png_image_write_to_memory(&image, png.data(), &size, 0, t.rgba.data(), 0, nullptr)) return nullptr;
  auto* tex = new aiTexture;
  tex->mWidth = static_cast<unsigned>(size);  // compressed: mWidth is the byte count, mHeight 0
  tex->mHeight = 0;
  std::strcpy(tex->achFormatHint, "png");
  tex->pcData = new aiTexel[(size + sizeof(aiTexel) - 1) / sizeof(aiTexel)];
  std::memcpy(tex->pcData, png.data(), size);
  return tex;
}

// texture: the index of its embedded base colour texture in the scene, or -1 for none.
aiMaterial* export_material(const SkinnedMesh& src, int texture) {
  auto* mat = new aiMaterial;
  const aiString name(src.name + "_material");
  mat->AddProperty(&name, AI_MATKEY_NAME);
  const aiColor4D base(src.base_color.x(), src.base_color.y(), src.base_color.z(), src.base_color.w());
  mat->AddProperty(&base, 1, AI_MATKEY_BASE_COLOR);
  mat->AddProperty(&base, 1, AI_MATKEY_COLOR_DIFFUSE);
  if (texture >= 0) {
    // "*N": the scene's embedded texture N, as assimp's importers name them.
    char name_of_texture[16];  // (built with snprintf: GCC 12 misreads "*" + std::to_string as overlapping)
    std::snprintf(name_of_texture, sizeof(name_of_texture), "*%d", texture);
    aiString where;
    where.Set(name_of_texture);
    mat->AddProperty(&where, AI_MATKEY_TEXTURE(aiTextureType_BASE_COLOR, 0));
    mat->AddProperty(&where, AI_MATKEY_TEXTURE(aiTextureType_DIFFUSE, 0));
  }
  return mat;
}

template <class Key, class Value, class Convert>
Key* export_keys(const std::vector<float>& times, const std::vector<Value>& values, Convert convert) {
  Key* keys = new Key[times.size()];
  for (std::size_t k = 0; k < times.size(); ++k) {
    keys[k].mTime = static_cast<double>(times[k]) * kExportTicksPerSecond;
    keys[k].mValue = convert(values[k]);
  }
  return keys;
}

aiAnimation* export_clip(const Clip& clip, const Skeleton& sk, const std::string& clock_node) {
  auto* a = new aiAnimation;
  a->mName = aiString(clip.name);
  a->mTicksPerSecond = kExportTicksPerSecond;
  a->mDuration = static_cast<double>(clip.duration) * kExportTicksPerSecond;
  const std::size_t joints = std::min(clip.tracks.size(), sk.size());
  a->mNumChannels = static_cast<unsigned>(joints + 1);
  a->mChannels = new aiNodeAnim*[joints + 1];
  auto vec = [](const Vec3& v) { return to_ai(v); };
  auto quat = [](const Quat& q) { return to_ai(q); };
  for (std::size_t j = 0; j < joints; ++j) {
    const JointTrack& t = clip.tracks[j];
    auto* ch = new aiNodeAnim;
    ch->mNodeName = aiString(sk.names[j]);
    ch->mNumPositionKeys = static_cast<unsigned>(t.translation_times.size());
    ch->mPositionKeys = export_keys<aiVectorKey>(t.translation_times, t.translations, vec);
    ch->mNumRotationKeys = static_cast<unsigned>(t.rotation_times.size());
    ch->mRotationKeys = export_keys<aiQuatKey>(t.rotation_times, t.rotations, quat);
    ch->mNumScalingKeys = static_cast<unsigned>(t.scale_times.size());
    ch->mScalingKeys = export_keys<aiVectorKey>(t.scale_times, t.scales, vec);
    a->mChannels[j] = ch;
  }
  // The clock: the mesh node held at its (identity) transform from 0 to the duration, so the
  // file's latest key time, which glTF readers take as the duration, is the clip's.
  auto* clock = new aiNodeAnim;
  clock->mNodeName = aiString(clock_node);
  std::vector<float> times = {0.0f};
  if (clip.duration > 0.0f) times.push_back(clip.duration);
  clock->mNumPositionKeys = static_cast<unsigned>(times.size());
  clock->mPositionKeys = export_keys<aiVectorKey>(times, std::vector<Vec3>(times.size(), Vec3::Zero()), vec);
  clock->mNumRotationKeys = static_cast<unsigned>(times.size());
  clock->mRotationKeys = export_keys<aiQuatKey>(times, std::vector<Quat>(times.size(), Quat::Identity()), quat);
  clock->mNumScalingKeys = static_cast<unsigned>(times.size());
  clock->mScalingKeys = export_keys<aiVectorKey>(times, std::vector<Vec3>(times.size(), Vec3::Ones()), vec);
  a->mChannels[joints] = clock;
  return a;
}

// The scene assimp writes. Its destructor frees everything, so every array is new[]-ed and
// every object new-ed, as assimp's own importers do.
std::unique_ptr<aiScene> build_scene(const Model& model, const std::string& path) {
  const Skeleton& sk = model.skeleton;
  if (sk.size() == 0) fail(path, "the model has no skeleton");
  if (model.meshes.empty()) fail(path, "the model has no mesh");
  auto scene = std::make_unique<aiScene>();

  // Joint nodes with their rest TRS, children in joint order.
  std::vector<aiNode*> nodes(sk.size());
  for (std::size_t j = 0; j < sk.size(); ++j) {
    nodes[j] = new aiNode(sk.names[j]);
    nodes[j]->mTransformation = aiMatrix4x4(to_ai(sk.rest_scale[j]), to_ai(sk.rest_rotation[j].normalized()),
                                            to_ai(sk.rest_translation[j]));
  }
  std::vector<std::vector<aiNode*>> children(sk.size());
  std::vector<std::size_t> roots;
  for (std::size_t j = 0; j < sk.size(); ++j) {
    if (sk.parents[j] < 0)
      roots.push_back(j);
    else
      children[static_cast<std::size_t>(sk.parents[j])].push_back(nodes[j]);
  }
  // The scene's root node holds the meshes' nodes, so it must stay where the model's origin is:
  // assimp writes the root's transform as a matrix, which glTF forbids on an animated node, and
  // viewers that (against the spec) move a skinned mesh with its node would lift it. A single
  // root joint that is such a node already (identity rest, weights no vertex: the Wuson's
  // "$dummy_root") is the root; otherwise a plain "root" node is added above the root joints,
  // which import reads as one more joint (identity, so no vertex moves; a second round trip
  // adds nothing).
  const bool plain_root = roots.size() == 1 && !sk.is_bone[roots[0]] &&
                          sk.rest_translation[roots[0]].isZero(0.0f) &&
                          sk.rest_rotation[roots[0]].coeffs().isApprox(Quat::Identity().coeffs(), 1e-7f) &&
                          sk.rest_scale[roots[0]].isApprox(Vec3::Ones(), 1e-7f);
  std::string root_name = "root";
  while (sk.find(root_name) >= 0) root_name += "_";
  aiNode* root = plain_root ? nodes[roots[0]] : new aiNode(root_name);
  if (plain_root) root->mTransformation = aiMatrix4x4();
  scene->mRootNode = root;
  for (std::size_t j = 0; j < sk.size(); ++j)
    if (nodes[j] != root) set_children(nodes[j], children[j]);

  // One node per mesh (assimp's glTF exporter writes only meshes a node holds), under the root.
  const std::size_t meshes = model.meshes.size();
  scene->mNumMeshes = static_cast<unsigned>(meshes);
  scene->mMeshes = new aiMesh*[meshes]();
  scene->mNumMaterials = static_cast<unsigned>(meshes);
  scene->mMaterials = new aiMaterial*[meshes]();
  // The root's children: the root joint's own, or the root joints.
  std::vector<aiNode*> top;
  if (plain_root)
    top = children[roots[0]];
  else
    for (std::size_t j : roots) top.push_back(nodes[j]);
  std::vector<std::string> mesh_nodes;
  // At most one texture a mesh; owned by the scene from the start, so a failure frees it.
  scene->mTextures = new aiTexture*[meshes]();
  for (std::size_t i = 0; i < meshes; ++i) {
    const SkinnedMesh& src = model.meshes[i];
    if (src.weights.size() != src.positions.size() || src.bones.size() != src.positions.size())
      fail(path, "mesh '" + src.name + "' does not weight every vertex");
    scene->mMeshes[i] = export_mesh(src, sk, static_cast<unsigned>(i));
    int texture = -1;
    if (src.base_color_texture && src.uvs.size() == src.positions.size()) {
      if (aiTexture* t = export_texture(*src.base_color_texture)) {
        texture = static_cast<int>(scene->mNumTextures);
        scene->mTextures[scene->mNumTextures++] = t;
      }
    }
    scene->mMaterials[i] = export_material(src, texture);
    // A node name must not be a joint's: bones find their nodes by name.
    std::string name = src.name.empty() ? "mesh" : src.name;
    while (sk.find(name) >= 0 || std::find(mesh_nodes.begin(), mesh_nodes.end(), name) != mesh_nodes.end())
      name += "_mesh" + std::to_string(i);
    mesh_nodes.push_back(name);
    auto* node = new aiNode(name);
    node->mNumMeshes = 1;
    node->mMeshes = new unsigned[1]{static_cast<unsigned>(i)};
    top.push_back(node);
  }
  set_children(root, top);
  if (scene->mNumTextures == 0) {
    delete[] scene->mTextures;
    scene->mTextures = nullptr;
  }

  scene->mNumAnimations = static_cast<unsigned>(model.clips.size());
  if (!model.clips.empty()) {
    scene->mAnimations = new aiAnimation*[model.clips.size()];
    for (std::size_t c = 0; c < model.clips.size(); ++c)
      scene->mAnimations[c] = export_clip(model.clips[c], sk, mesh_nodes.front());
  }
  return scene;
}

}  // namespace

void export_model_gltf(const Model& model, const std::string& path) {
  const std::filesystem::path file(path);
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext != ".glb" && ext != ".gltf") fail(path, "expected a .glb or .gltf file name");
  const bool binary = ext == ".glb";
  // Refused before the work, with the reason the folder gives (missing, read-only, ...).
  check_writable(path);

  std::unique_ptr<aiScene> scene = build_scene(model, path);
  Assimp::Exporter exporter;
  Assimp::ExportProperties properties;
  // The JSON's buffer is named after the file: FILE.gltf refers to FILE.bin beside it.
  const std::string stem = file.stem().string();
  properties.SetPropertyString(AI_CONFIG_EXPORT_BLOB_NAME, stem);
  const aiExportDataBlob* blob = exporter.ExportToBlob(scene.get(), binary ? "glb2" : "gltf2", 0u, &properties);
  if (!blob) fail(path, std::string("assimp could not write it: ") + exporter.GetErrorString());
  // The buffer first, then the JSON that refers to it, each renamed into place whole.
  std::string main_bytes(static_cast<const char*>(blob->data), blob->size);
  for (const aiExportDataBlob* extra = blob->next; extra; extra = extra->next) {
    const std::string name = extra->name.C_Str();
    const std::string beside_name = name.find('.') == std::string::npos ? stem + "." + name : name;
    const std::filesystem::path beside = file.parent_path() / beside_name;
    write_file_atomically(beside.string(), std::string_view(static_cast<const char*>(extra->data), extra->size));
  }
  write_file_atomically(path, main_bytes);
}

}  // namespace ballpit
