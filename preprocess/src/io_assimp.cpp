// Triangle surfaces through assimp, for the formats CGAL does not read (glTF, FBX, 3DS, ...;
// io_surface.cpp dispatches). The only translation unit that includes assimp.

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/Importer.hpp>

#include <cmath>
#include <map>
#include <string>

#include "tetseg/preprocess/io.hpp"

namespace tetseg::preprocess::detail {

/// Reads the triangles of every mesh of the scene (see read_triangle_mesh). Throws InputError.
TriangleMesh read_triangle_mesh_assimp(const std::string& path) {
  Assimp::Importer importer;
  // Points and lines are dropped; everything else is flattened into world coordinates.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* scene =
      importer.ReadFile(path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                  aiProcess_SortByPType | aiProcess_PreTransformVertices);
  if (scene == nullptr) {
    std::string reason = importer.GetErrorString();
    if (reason.empty()) reason = "unknown error";
    throw InputError(path, "cannot read surface mesh: " + reason);
  }
  TriangleMesh mesh;
  // Vertices are merged by exact position (STL and per-face normals duplicate them), numbered
  // in order of first use.
  std::map<Vec3, std::uint32_t> index_of;
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
        const aiVector3D& v = am->mVertices[vi];
        const Vec3 p = {static_cast<double>(v.x), static_cast<double>(v.y),
                        static_cast<double>(v.z)};
        if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
          throw InputError(path, "vertex coordinate is not finite");
        const auto [it, inserted] =
            index_of.emplace(p, static_cast<std::uint32_t>(mesh.vertices.size()));
        if (inserted) mesh.vertices.push_back(p);
        tri[k] = it->second;
      }
      mesh.triangles.push_back(tri);
    }
  }
  return mesh;
}

}  // namespace tetseg::preprocess::detail
