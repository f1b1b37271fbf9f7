// Triangle surfaces through assimp, for the formats CGAL does not read (glTF, FBX, 3DS, ...;
// io_surface.cpp dispatches). The only translation unit that includes assimp.

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/Importer.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include "tetseg/preprocess/io.hpp"
#include "tetseg/preprocess/skin.hpp"

namespace tetseg::preprocess::detail {

/// Reads the triangles of every mesh of the scene (see read_triangle_mesh). Throws InputError.
/// `keep_vertices` (surface bodies): assimp keeps the file's vertices (no joining), every one
/// of them becomes a vertex (merged by exact position as always, unused ones after the used
/// ones), and `source_vertex_nodes` (if given) records each file vertex's vertex: every mesh
/// assimp reports, in its order, each mesh's vertices in order (one mesh: the file's order).
TriangleMesh read_triangle_mesh_assimp(const std::string& path, bool keep_vertices,
                                       std::vector<std::uint32_t>* source_vertex_nodes) {
  Assimp::Importer importer;
  // Points and lines are dropped; everything else is flattened into world coordinates.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const unsigned join = keep_vertices ? 0u : unsigned(aiProcess_JoinIdenticalVertices);
  const aiScene* scene = importer.ReadFile(
      path, aiProcess_Triangulate | join | aiProcess_SortByPType | aiProcess_PreTransformVertices);
  if (scene == nullptr) {
    std::string reason = importer.GetErrorString();
    if (reason.empty()) reason = "unknown error";
    throw InputError(path, "cannot read surface mesh: " + reason);
  }
  TriangleMesh mesh;
  // Vertices are merged by exact position (STL and per-face normals duplicate them), numbered
  // in order of first use.
  std::map<Vec3, std::uint32_t> index_of;
  auto position = [&](const aiVector3D& v) {
    const Vec3 p = {static_cast<double>(v.x), static_cast<double>(v.y), static_cast<double>(v.z)};
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      throw InputError(path, "vertex coordinate is not finite");
    return p;
  };
  auto node_of = [&](const Vec3& p) {
    const auto [it, inserted] =
        index_of.emplace(p, static_cast<std::uint32_t>(mesh.vertices.size()));
    if (inserted) mesh.vertices.push_back(p);
    return it->second;
  };
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* am = scene->mMeshes[m];
    if (am == nullptr || am->mVertices == nullptr) continue;
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices != 3) continue;
      Tri tri;
      for (unsigned k = 0; k < 3; ++k) {
        const unsigned vi = face.mIndices[k];
        if (vi >= am->mNumVertices)
          throw InputError(path, "face refers to vertex " + std::to_string(vi) + " out of range");
        tri[k] = node_of(position(am->mVertices[vi]));
      }
      mesh.triangles.push_back(tri);
    }
  }
  if (!keep_vertices) return mesh;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* am = scene->mMeshes[m];
    if (am == nullptr || am->mVertices == nullptr) continue;
    for (unsigned v = 0; v < am->mNumVertices; ++v) {
      const std::uint32_t node = node_of(position(am->mVertices[v]));
      if (source_vertex_nodes) source_vertex_nodes->push_back(node);
    }
  }
  return mesh;
}

}  // namespace tetseg::preprocess::detail

namespace tetseg::preprocess {

Skin read_skin(const std::string& path) {
  Assimp::Importer importer;
  // No joining and no pre-transforming: vertices stay the file's, in its order, in mesh space
  // (the bind pose the inverse bind matrices refer to). Validation refuses weights that name
  // vertices out of range and faces with bad indices.
  const aiScene* scene =
      importer.ReadFile(path, aiProcess_Triangulate | aiProcess_ValidateDataStructure);
  if (scene == nullptr) {
    std::string reason = importer.GetErrorString();
    if (reason.empty()) reason = "unknown error";
    throw InputError(path, "cannot read skinned mesh: " + reason);
  }
  Skin skin;
  std::map<std::string, std::uint32_t> bone_of_name;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* am = scene->mMeshes[m];
    if (am == nullptr || am->mVertices == nullptr) continue;
    const std::string mesh_name =
        "mesh " + std::to_string(m) +
        (am->mName.length ? " '" + std::string(am->mName.C_Str()) + "'" : std::string());
    if (am->mNumBones == 0 || am->mBones == nullptr)
      throw InputError(path, mesh_name + " has no bones (no skin)");
    const auto first = static_cast<std::uint32_t>(skin.vertices.size());
    for (unsigned v = 0; v < am->mNumVertices; ++v) {
      const aiVector3D& p = am->mVertices[v];
      const Vec3 q = {double(p.x), double(p.y), double(p.z)};
      if (!std::isfinite(q[0]) || !std::isfinite(q[1]) || !std::isfinite(q[2]))
        throw InputError(path, mesh_name + ": vertex " + std::to_string(v) + " is not finite");
      skin.vertices.push_back(q);
    }
    skin.influences.resize(skin.vertices.size());
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines
      Tri tri;
      for (unsigned k = 0; k < 3; ++k) {
        if (face.mIndices[k] >= am->mNumVertices)
          throw InputError(
              path, mesh_name + ": face " + std::to_string(f) + " refers to a vertex out of range");
        tri[k] = first + face.mIndices[k];
      }
      skin.triangles.push_back(tri);
    }
    for (unsigned b = 0; b < am->mNumBones; ++b) {
      const aiBone* bone = am->mBones[b];
      if (bone == nullptr)
        throw InputError(path, mesh_name + ": bone " + std::to_string(b) + " is missing");
      const std::string name = bone->mName.C_Str();
      const aiMatrix4x4& o = bone->mOffsetMatrix;
      const Affine3x4 bind = {o.a1, o.a2, o.a3, o.a4, o.b1, o.b2,
                              o.b3, o.b4, o.c1, o.c2, o.c3, o.c4};
      const bool finite =
          std::all_of(bind.begin(), bind.end(), [](double x) { return std::isfinite(x); });
      if (!finite || o.d1 != 0 || o.d2 != 0 || o.d3 != 0 || o.d4 != 1)
        throw InputError(path, mesh_name + ": bone '" + name +
                                   "': inverse bind matrix is not a finite affine matrix");
      const auto [it, inserted] =
          bone_of_name.emplace(name, static_cast<std::uint32_t>(skin.bone_names.size()));
      if (inserted) {
        skin.bone_names.push_back(name);
        skin.inverse_bind.push_back(bind);
      } else if (skin.inverse_bind[it->second] != bind) {
        throw InputError(path, "bone '" + name + "' has two different inverse bind matrices");
      }
      for (unsigned k = 0; k < bone->mNumWeights; ++k) {
        const aiVertexWeight& w = bone->mWeights[k];
        if (w.mVertexId >= am->mNumVertices)
          throw InputError(path, mesh_name + ": bone '" + name + "' weights vertex " +
                                     std::to_string(w.mVertexId) + " of " +
                                     std::to_string(am->mNumVertices));
        if (!std::isfinite(w.mWeight) || w.mWeight < 0)
          throw InputError(path, mesh_name + ": bone '" + name + "' has weight " +
                                     std::to_string(w.mWeight) + " on vertex " +
                                     std::to_string(w.mVertexId) +
                                     " (weights must be finite and >= 0)");
        if (w.mWeight == 0) continue;
        auto& list = skin.influences[first + w.mVertexId];
        const auto same = std::find_if(
            list.begin(), list.end(), [&](const BoneInfluence& i) { return i.bone == it->second; });
        if (same != list.end())
          same->weight += w.mWeight;
        else
          list.push_back({it->second, double(w.mWeight)});
      }
    }
    for (std::size_t v = first; v < skin.vertices.size(); ++v) {
      auto& list = skin.influences[v];
      if (list.empty())
        throw InputError(
            path, mesh_name + ": vertex " + std::to_string(v - first) + " has no bone weights");
      double total = 0;
      for (const auto& i : list) total += i.weight;
      // assimp's glTF importer drops weights <= 0, NaN and joints past the skin's before we
      // see them; what is left of such a vertex no longer sums to 1, so this refuses it too.
      if (!(std::fabs(total - 1) <= kSkinWeightSumTolerance))
        throw InputError(path, mesh_name + ": the bone weights of vertex " +
                                   std::to_string(v - first) + " sum to " + std::to_string(total) +
                                   ", not 1");
      for (auto& i : list) i.weight /= total;
      std::sort(list.begin(), list.end(),
                [](const BoneInfluence& a, const BoneInfluence& b) { return a.bone < b.bone; });
    }
  }
  if (skin.triangles.empty()) throw InputError(path, "no triangles in file");
  return skin;
}

}  // namespace tetseg::preprocess
