#include "renderer/scene/mesh_loader.h"

#include "common/error.h"
#include "renderer/scene/tangent_space.h"

#include <assimp/Importer.hpp>
#include <assimp/config.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace skinlab::renderer {
namespace {

[[noreturn]] void failModel(const std::filesystem::path& path, const std::string& why) {
    std::string message = why;
    std::replace(message.begin(), message.end(), '\n', ' '); // keep the error on one line
    while (!message.empty() && (message.back() == ' ' || message.back() == '\r')) message.pop_back();
    throw InputError(path.string() + ": cannot load model (" + message + ")");
}

glm::mat4 toGlm(const aiMatrix4x4& m) {
    // aiMatrix4x4 is row-major (a1..a4 is the first row); glm is column-major.
    return glm::mat4(m.a1, m.b1, m.c1, m.d1, m.a2, m.b2, m.c2, m.d2, m.a3, m.b3, m.c3, m.d3, m.a4, m.b4, m.c4, m.d4);
}

MeshMaterial convertMaterial(const aiMaterial& source, unsigned index) {
    MeshMaterial material;
    aiString name;
    if (source.Get(AI_MATKEY_NAME, name) == AI_SUCCESS && name.length > 0) {
        material.name = name.C_Str();
    } else {
        material.name = "material-" + std::to_string(index);
    }
    // glTF baseColorFactor is linear by the glTF specification; OBJ Kd has no defined encoding and is taken
    // as linear as well (as assimp and most renderers do).
    aiColor4D colour;
    if (source.Get(AI_MATKEY_BASE_COLOR, colour) == AI_SUCCESS ||
        source.Get(AI_MATKEY_COLOR_DIFFUSE, colour) == AI_SUCCESS) {
        material.albedo = glm::vec3(colour.r, colour.g, colour.b);
    }
    material.skin = true; // the scene spec decides which materials are skin
    return material;
}

struct Collector {
    const aiScene& scene;
    Model& model;
    // One SubMesh per (node, mesh) instance, in scene-graph order.
    void visit(const aiNode& node, const glm::mat4& parent) {
        const glm::mat4 world = parent * toGlm(node.mTransformation);
        const glm::mat3 normalMatrix = glm::transpose(glm::inverse(glm::mat3(world)));
        // A mirroring transform (negative determinant) turns counter-clockwise triangles clockwise: swap two
        // corners so front faces stay front faces.
        const bool mirrored = glm::determinant(glm::mat3(world)) < 0.0f;
        for (unsigned m = 0; m < node.mNumMeshes; ++m) {
            const aiMesh& mesh = *scene.mMeshes[node.mMeshes[m]];
            if (!(mesh.mPrimitiveTypes & aiPrimitiveType_TRIANGLE) || mesh.mNumFaces == 0) continue;
            const auto base = static_cast<std::uint32_t>(model.vertices.size());
            const bool hasUv = mesh.HasTextureCoords(0);
            for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
                Vertex vertex;
                const aiVector3D& p = mesh.mVertices[v];
                vertex.position = glm::vec3(world * glm::vec4(p.x, p.y, p.z, 1.0f));
                glm::vec3 normal(0.0f, 0.0f, 1.0f);
                if (mesh.HasNormals()) {
                    const aiVector3D& n = mesh.mNormals[v];
                    normal = normalMatrix * glm::vec3(n.x, n.y, n.z);
                }
                const float length = glm::length(normal);
                // A zero normal (assimp writes NaN/0 for vertices of degenerate faces) falls back to +Z.
                vertex.normal = (length > 0.0f && std::isfinite(length)) ? normal / length : glm::vec3(0, 0, 1);
                if (hasUv) vertex.uv = glm::vec2(mesh.mTextureCoords[0][v].x, mesh.mTextureCoords[0][v].y);
                model.vertices.push_back(vertex);
            }
            const auto first = static_cast<std::uint32_t>(model.indices.size());
            for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
                const aiFace& face = mesh.mFaces[f];
                if (face.mNumIndices != 3) continue; // points and lines left by SortByPType
                model.indices.push_back(base + face.mIndices[0]);
                model.indices.push_back(base + face.mIndices[mirrored ? 2 : 1]);
                model.indices.push_back(base + face.mIndices[mirrored ? 1 : 2]);
            }
            const auto count = static_cast<std::uint32_t>(model.indices.size()) - first;
            if (count > 0) model.parts.push_back(SubMesh{first, count, mesh.mMaterialIndex});
        }
        for (unsigned c = 0; c < node.mNumChildren; ++c) visit(*node.mChildren[c], world);
    }
};

} // namespace

Model loadModel(const std::filesystem::path& path, const ModelLoadOptions& options) {
    std::error_code code;
    if (!std::filesystem::is_regular_file(path, code)) failModel(path, "no such file");

    Assimp::Importer importer;
    // Smooth normals generated only where the file has none; edges sharper than 80° stay sharp.
    importer.SetPropertyFloat(AI_CONFIG_PP_GSN_MAX_SMOOTHING_ANGLE, 80.0f);
    // Drop points and lines entirely; remove (not just flag) degenerate triangles.
    importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    importer.SetPropertyBool(AI_CONFIG_PP_FD_REMOVE, true);
    const unsigned flags = aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_GenSmoothNormals |
                           aiProcess_SortByPType | aiProcess_FindDegenerates | aiProcess_FindInvalidData |
                           aiProcess_ValidateDataStructure |
                           // assimp stores UVs with v = 0 at the image bottom (it flips glTF's on import);
                           // flipping back gives v = 0 at the top, the convention of Model and Image.
                           aiProcess_FlipUVs;
    const aiScene* scene = importer.ReadFile(path.string(), flags);
    if (scene == nullptr) failModel(path, std::string("assimp: ") + importer.GetErrorString());
    if ((scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) != 0 || scene->mRootNode == nullptr) {
        failModel(path, "assimp: incomplete scene");
    }

    Model model;
    for (unsigned m = 0; m < scene->mNumMaterials; ++m)
        model.materials.push_back(convertMaterial(*scene->mMaterials[m], m));
    if (model.materials.empty()) model.materials.push_back(MeshMaterial{.name = "material-0"});
    Collector{*scene, model}.visit(*scene->mRootNode, glm::mat4(1.0f));
    if (model.indices.empty()) failModel(path, "no triangle meshes");
    for (SubMesh& part : model.parts) {
        if (part.material >= model.materials.size()) part.material = 0;
    }
    if (options.flipV) {
        for (Vertex& vertex : model.vertices) vertex.uv.y = 1.0f - vertex.uv.y;
    }
    computeTangents(model); // after any flip: the handedness depends on the direction of v
    model.computeBounds();
    return model;
}

} // namespace skinlab::renderer
