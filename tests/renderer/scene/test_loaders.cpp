// Mesh loading through assimp (mesh_loader.h) and texture loading through OpenImageIO + OpenColorIO
// (texture.h): small files written by the tests themselves, the scanned head when $SKINLAB_ASSETS is set,
// and every bad-file case.
#include "common/error.h"
#include "renderer/scene/mesh_loader.h"
#include "renderer/scene/texture.h"
#include "tests/common/temp_folder.h"

#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>
#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <string>
#include <unistd.h>

namespace skinlab::renderer {
namespace {

namespace fs = std::filesystem;

// A fresh folder per test (tests/common/temp_folder.h), removed afterwards.
class InTempFolder : public ::testing::Test {
protected:
    fs::path write(const std::string& name, const std::string& content) const { return folder_.write(name, content); }
    const test_support::TempFolder folder_;
};

std::string expectInputError(const std::function<void()>& f) {
    try {
        f();
    } catch (const InputError& error) {
        return error.what();
    }
    ADD_FAILURE() << "expected InputError";
    return {};
}

// --- OBJ ----------------------------------------------------------------------------------------------------

// A cube of side 2 × scale: quads (triangulated on import), UVs per face, no normals (generated), two
// materials from an .mtl file.
constexpr const char* kCubeObj = R"(mtllib cube.mtl
v -1 -1  1
v  1 -1  1
v  1  1  1
v -1  1  1
v -1 -1 -1
v  1 -1 -1
v  1  1 -1
v -1  1 -1
vt 0 0
vt 1 0
vt 1 1
vt 0 1
usemtl skinMaterial
f 1/1 2/2 3/3 4/4
f 6/1 5/2 8/3 7/4
usemtl paintMaterial
f 2/1 6/2 7/3 3/4
f 5/1 1/2 4/3 8/4
f 4/1 3/2 7/3 8/4
f 5/1 6/2 2/3 1/4
)";
constexpr const char* kCubeMtl = R"(newmtl skinMaterial
Kd 0.8 0.6 0.5
newmtl paintMaterial
Kd 0.1 0.2 0.3
)";

class ObjLoader : public InTempFolder {};

TEST_F(ObjLoader, TriangulatesGeneratesFlatNormalsAndKeepsMaterials) {
    write("cube.mtl", kCubeMtl);
    const Model model = loadModel(write("cube.obj", kCubeObj));
    EXPECT_EQ(model.indices.size(), 36u) << "6 quads → 12 triangles";
    EXPECT_EQ(model.boundsMin, glm::vec3(-1.0f));
    EXPECT_EQ(model.boundsMax, glm::vec3(1.0f));
    std::map<std::string, glm::vec3> albedo;
    for (const MeshMaterial& material : model.materials) albedo[material.name] = material.albedo;
    ASSERT_TRUE(albedo.count("skinMaterial"));
    ASSERT_TRUE(albedo.count("paintMaterial"));
    EXPECT_NEAR(albedo["paintMaterial"].b, 0.3f, 1e-6f);
    EXPECT_NEAR(albedo["skinMaterial"].r, 0.8f, 1e-6f);
    std::map<std::string, std::uint32_t> triangles;
    for (const SubMesh& part : model.parts) triangles[model.materials.at(part.material).name] += part.indexCount / 3;
    EXPECT_EQ(triangles["skinMaterial"], 4u);
    EXPECT_EQ(triangles["paintMaterial"], 8u);

    // The cube's edges are 90°, sharper than the 80° smoothing limit: every generated normal is its face's.
    for (std::size_t t = 0; t < model.indices.size(); t += 3) {
        const glm::vec3 a = model.vertices[model.indices[t]].position;
        const glm::vec3 b = model.vertices[model.indices[t + 1]].position;
        const glm::vec3 c = model.vertices[model.indices[t + 2]].position;
        const glm::vec3 face = glm::normalize(glm::cross(b - a, c - a));
        EXPECT_GT(glm::dot(face, glm::normalize(a)), 0.0f) << "counter-clockwise seen from outside";
        for (int k = 0; k < 3; ++k) {
            const Vertex& v = model.vertices[model.indices[t + static_cast<std::size_t>(k)]];
            EXPECT_NEAR(glm::length(v.normal - face), 0.0f, 1e-5f);
            EXPECT_NEAR(glm::dot(glm::vec3(v.tangent), v.normal), 0.0f, 1e-5f);
            EXPECT_NEAR(glm::length(glm::vec3(v.tangent)), 1.0f, 1e-5f);
        }
    }
}

TEST_F(ObjLoader, UvOriginIsTheImageTopAndTangentsFollowTheNormalMapConvention) {
    write("cube.mtl", kCubeMtl);
    const Model model = loadModel(write("cube.obj", kCubeObj));
    // Front face (+Z): OBJ vt (0, 0) is the image's bottom-left corner, at position (-1, -1, 1). In Model UVs
    // (v = 0 at the top) that corner is (0, 1).
    int checked = 0;
    for (const Vertex& v : model.vertices) {
        if (v.normal.z < 0.99f) continue;
        if (v.position == glm::vec3(-1, -1, 1)) {
            EXPECT_EQ(v.uv, glm::vec2(0, 1));
        }
        if (v.position == glm::vec3(1, 1, 1)) {
            EXPECT_EQ(v.uv, glm::vec2(1, 0));
        }
        // u grows along +X, the image's up is +Y: tangent +X, bitangent w·cross(N, T) = +Y, so w = +1.
        EXPECT_NEAR(glm::length(glm::vec3(v.tangent) - glm::vec3(1, 0, 0)), 0.0f, 1e-5f);
        EXPECT_EQ(v.tangent.w, 1.0f);
        const glm::vec3 bitangent = v.tangent.w * glm::cross(v.normal, glm::vec3(v.tangent));
        EXPECT_NEAR(bitangent.y, 1.0f, 1e-5f);
        ++checked;
    }
    EXPECT_EQ(checked, 4) << "the front face has 4 unique vertices after joining";
}

TEST_F(ObjLoader, FlipVOptionMirrorsUvsAndTangentHandedness) {
    write("cube.mtl", kCubeMtl);
    const fs::path path = write("cube.obj", kCubeObj);
    const Model plain = loadModel(path);
    const Model flipped = loadModel(path, ModelLoadOptions{.flipV = true});
    ASSERT_EQ(plain.vertices.size(), flipped.vertices.size());
    for (std::size_t i = 0; i < plain.vertices.size(); ++i) {
        EXPECT_EQ(flipped.vertices[i].uv.y, 1.0f - plain.vertices[i].uv.y);
        EXPECT_EQ(flipped.vertices[i].uv.x, plain.vertices[i].uv.x);
        EXPECT_EQ(flipped.vertices[i].tangent.w, -plain.vertices[i].tangent.w);
    }
}

// --- glTF ---------------------------------------------------------------------------------------------------

std::string base64(const std::string& bytes) {
    static const char* alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    std::size_t i = 0;
    for (; i + 2 < bytes.size(); i += 3) {
        const auto n = (static_cast<unsigned char>(bytes[i]) << 16) | (static_cast<unsigned char>(bytes[i + 1]) << 8) |
                       static_cast<unsigned char>(bytes[i + 2]);
        out += {alphabet[(n >> 18) & 63], alphabet[(n >> 12) & 63], alphabet[(n >> 6) & 63], alphabet[n & 63]};
    }
    if (i + 1 == bytes.size()) {
        const auto n = static_cast<unsigned char>(bytes[i]) << 16;
        out += {alphabet[(n >> 18) & 63], alphabet[(n >> 12) & 63], '=', '='};
    } else if (i + 2 == bytes.size()) {
        const auto n = (static_cast<unsigned char>(bytes[i]) << 16) | (static_cast<unsigned char>(bytes[i + 1]) << 8);
        out += {alphabet[(n >> 18) & 63], alphabet[(n >> 12) & 63], alphabet[(n >> 6) & 63], '='};
    }
    return out;
}

// One triangle in a child node (scale 2, rotation 90° about +Y) of a parent node (translation (10, 5, 0)).
std::string triangleGltf() {
    const float positions[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    const float normals[] = {0, 0, 1, 0, 0, 1, 0, 0, 1};
    const float uvs[] = {0, 0, 1, 0, 0, 1}; // glTF: v = 0 at the image top
    std::string buffer(reinterpret_cast<const char*>(positions), sizeof positions);
    buffer.append(reinterpret_cast<const char*>(normals), sizeof normals);
    buffer.append(reinterpret_cast<const char*>(uvs), sizeof uvs);
    const float s = std::sqrt(0.5f);
    return R"({
 "asset": {"version": "2.0"},
 "scene": 0,
 "scenes": [{"nodes": [0]}],
 "nodes": [{"translation": [10, 5, 0], "children": [1]},
           {"mesh": 0, "scale": [2, 2, 2], "rotation": [0, )" +
           std::to_string(s) + ", 0, " + std::to_string(s) + R"(]}],
 "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "material": 0}]}],
 "materials": [{"name": "skin-material", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.25, 0.125, 1]}}],
 "buffers": [{"byteLength": )" +
           std::to_string(buffer.size()) + R"(, "uri": "data:application/octet-stream;base64,)" + base64(buffer) +
           R"("}],
 "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                 {"buffer": 0, "byteOffset": 36, "byteLength": 36},
                 {"buffer": 0, "byteOffset": 72, "byteLength": 24}],
 "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
               {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3"},
               {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"}]
})";
}

class GltfLoader : public InTempFolder {};

TEST_F(GltfLoader, AppliesNestedNodeTransformsToPositionsAndNormals) {
    const Model model = loadModel(write("triangle.gltf", triangleGltf()));
    ASSERT_EQ(model.indices.size(), 3u);
    ASSERT_EQ(model.vertices.size(), 3u);
    // world = T(10, 5, 0) · R_y(90°) · S(2): (x, y, z) → (10 + 2z, 5 + 2y, -2x).
    const glm::vec3 expected[3] = {{10, 5, 0}, {10, 5, -2}, {10, 7, 0}};
    for (int k = 0; k < 3; ++k) {
        const Vertex& v = model.vertices[model.indices[static_cast<std::size_t>(k)]];
        // 1e-5: the rotation quaternion is given to 6 decimals in the file.
        EXPECT_NEAR(glm::length(v.position - expected[k]), 0.0f, 1e-5f) << k;
        EXPECT_NEAR(glm::length(v.normal - glm::vec3(1, 0, 0)), 0.0f, 1e-5f) << "normal +Z rotated to +X";
    }
    EXPECT_EQ(model.materials.at(model.parts.at(0).material).name, "skin-material");
    EXPECT_EQ(model.materials.at(model.parts.at(0).material).albedo, glm::vec3(0.5f, 0.25f, 0.125f));
}

TEST_F(GltfLoader, KeepsGltfUvsAndDerivesMirroredHandedness) {
    const Model model = loadModel(write("triangle.gltf", triangleGltf()));
    const glm::vec2 expectedUv[3] = {{0, 0}, {1, 0}, {0, 1}};
    for (int k = 0; k < 3; ++k) {
        const Vertex& v = model.vertices[model.indices[static_cast<std::size_t>(k)]];
        EXPECT_EQ(v.uv, expectedUv[k]) << "glTF UVs already have v = 0 at the top: unchanged";
        // u grows along the world direction of local +X: (0, 0, -1). v grows along local +Y = world +Y, so the
        // image's up is world -Y; cross(N, T) = cross(+X, -Z) = +Y, hence w = -1 (a mirrored layout).
        EXPECT_NEAR(glm::length(glm::vec3(v.tangent) - glm::vec3(0, 0, -1)), 0.0f, 1e-5f);
        EXPECT_EQ(v.tangent.w, -1.0f);
    }
}

// --- bad model files ----------------------------------------------------------------------------------------

class BadModel : public InTempFolder {};

TEST_F(BadModel, MissingFileNamesThePath) {
    const fs::path path = folder_ / "absent.glb";
    EXPECT_EQ(expectInputError([&] { loadModel(path); }), path.string() + ": cannot load model (no such file)");
}

TEST_F(BadModel, GarbageBytesNameThePathAndAssimp) {
    for (const char* name : {"garbage.glb", "garbage.gltf", "garbage.obj"}) {
        const fs::path path = write(name, std::string("\x01\x02\xff\xfe garbage \x00\x13 not a model", 31));
        const std::string message = expectInputError([&] { loadModel(path); });
        EXPECT_EQ(message.rfind(path.string() + ": cannot load model (", 0), 0u) << message;
        EXPECT_EQ(message.find('\n'), std::string::npos) << "one line";
        EXPECT_EQ(message.back(), ')') << message;
    }
}

TEST_F(BadModel, FileWithoutTrianglesIsAnError) {
    const fs::path path = write("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
    const std::string message = expectInputError([&] { loadModel(path); });
    EXPECT_EQ(message.rfind(path.string() + ": cannot load model (", 0), 0u) << message;
}

TEST_F(BadModel, TruncatedGlbIsAnError) {
    // A valid glTF made binary-looking: the "glTF" magic followed by nonsense lengths.
    const fs::path path = write("truncated.glb", std::string("glTF\x02\x00\x00\x00\xff\xff\xff\x7f", 12));
    const std::string message = expectInputError([&] { loadModel(path); });
    EXPECT_EQ(message.rfind(path.string() + ": cannot load model (assimp: ", 0), 0u) << message;
}

// --- the scanned head ($SKINLAB_ASSETS) ---------------------------------------------------------------------

fs::path scannedHead() {
    const char* assets = std::getenv("SKINLAB_ASSETS");
    if (assets == nullptr || *assets == '\0') return {};
    return fs::path(assets) / "LeePerrySmith" / "LeePerrySmith.glb";
}

TEST(ScannedHead, LoadsWithDocumentedCountsAndOrientation) {
    const fs::path path = scannedHead();
    if (path.empty()) GTEST_SKIP() << "SKINLAB_ASSETS is not set; the scanned-head test needs LeePerrySmith.glb";
    const Model model = loadModel(path, ModelLoadOptions{.flipV = true});
    EXPECT_EQ(model.indices.size() / 3, 17684u) << "triangle count stated in shared/assets/README.md";
    for (const Vertex& v : model.vertices) {
        ASSERT_NEAR(glm::length(v.normal), 1.0f, 1e-4f);
        ASSERT_NEAR(std::abs(glm::dot(glm::vec3(v.tangent), v.normal)), 0.0f, 1e-4f);
        ASSERT_GE(v.uv.x, 0.0f);
        ASSERT_LE(v.uv.x, 1.0f);
        ASSERT_GE(v.uv.y, 0.0f);
        ASSERT_LE(v.uv.y, 1.0f);
    }
    // +Y up, facing +Z: the most anterior point (the nose tip) is near the midline in the upper half.
    const Vertex* front = &model.vertices.front();
    for (const Vertex& v : model.vertices) {
        if (v.position.z > front->position.z) front = &v;
    }
    EXPECT_LT(std::abs(front->position.x), 0.2f);
    EXPECT_GT(front->position.y, 0.0f);
    // With flipV the texture's up is the head's up: v (0 = image top) falls as y rises over the face. Without
    // it the colour map lands upside down (docs/assets.md).
    double sumY = 0, sumV = 0, sumYY = 0, sumVV = 0, sumYV = 0;
    for (const Vertex& v : model.vertices) {
        sumY += v.position.y;
        sumV += v.uv.y;
        sumYY += double(v.position.y) * v.position.y;
        sumVV += double(v.uv.y) * v.uv.y;
        sumYV += double(v.position.y) * v.uv.y;
    }
    const double n = static_cast<double>(model.vertices.size());
    const double correlation = (sumYV / n - sumY / n * sumV / n) /
                               std::sqrt((sumYY / n - sumY / n * sumY / n) * (sumVV / n - sumV / n * sumV / n));
    EXPECT_LT(correlation, -0.5);
    // Same head, same texture: most tangent frames are right-handed after the flip (the unwrap is not mirrored).
    std::size_t rightHanded = 0;
    for (const Vertex& v : model.vertices) rightHanded += v.tangent.w > 0.0f ? 1u : 0u;
    EXPECT_GT(rightHanded, model.vertices.size() * 9 / 10);
}

// Millimetres per unit of LeePerrySmith.glb as derived in docs/assets.md ("The scanned head's scale").
constexpr double kScannedHeadMillimetresPerUnit = 47.9;

// Points where the triangle edges of the model cross the plane p[axis] = value (a cross-section contour).
std::vector<glm::vec3> crossSection(const Model& model, int axis, float value) {
    std::vector<glm::vec3> points;
    for (std::size_t t = 0; t < model.indices.size(); t += 3) {
        for (std::size_t k = 0; k < 3; ++k) {
            const glm::vec3 a = model.vertices[model.indices[t + k]].position;
            const glm::vec3 b = model.vertices[model.indices[t + (k + 1) % 3]].position;
            const float da = a[axis] - value;
            const float db = b[axis] - value;
            if ((da < 0.0f) != (db < 0.0f)) points.push_back(a + (b - a) * (da / (da - db)));
        }
    }
    return points;
}

// The measurement of docs/assets.md, repeated on the file: head length glabella–opisthocranion in the
// midsagittal plane (through the nose tip), head breadth eurion–eurion (widest horizontal section above the
// ears, i.e. above the glabella), in file units.
TEST(ScannedHead, AnthropometricScaleMatchesTheDocumentedValue) {
    const fs::path path = scannedHead();
    if (path.empty()) GTEST_SKIP() << "SKINLAB_ASSETS is not set; the scanned-head test needs LeePerrySmith.glb";
    const Model model = loadModel(path, ModelLoadOptions{.flipV = true});
    const Vertex* tip = &model.vertices.front();
    for (const Vertex& v : model.vertices) {
        if (v.position.z > tip->position.z) tip = &v;
    }
    const std::vector<glm::vec3> sagittal = crossSection(model, 0, tip->position.x);
    // Glabella: the most anterior point of the midline contour above the nose (the forehead between the brows,
    // above the nasion's notch at ~0.7 units over the tip); opisthocranion: the most posterior point of the
    // midline contour of the skull (above the nose tip: the neck and shoulders lie below).
    glm::vec3 glabella(0.0f, 0.0f, -1e30f);
    glm::vec3 opisthocranion(0.0f, 0.0f, 1e30f);
    for (const glm::vec3& p : sagittal) {
        if (p.y > tip->position.y + 0.9f && p.z > glabella.z) glabella = p;
        if (p.y > tip->position.y && p.z < opisthocranion.z) opisthocranion = p;
    }
    const double length = glabella.z - opisthocranion.z;
    double breadth = 0.0;
    for (float y = glabella.y; y < model.boundsMax.y; y += 0.01f) {
        float lowest = 1e30f;
        float highest = -1e30f;
        for (const glm::vec3& p : crossSection(model, 1, y)) {
            lowest = std::min(lowest, p.x);
            highest = std::max(highest, p.x);
        }
        if (highest > lowest) breadth = std::max(breadth, static_cast<double>(highest - lowest));
    }
    // Measured values written in docs/assets.md (units), to 0.01.
    EXPECT_NEAR(length, 4.186, 0.01);
    EXPECT_NEAR(breadth, 3.153, 0.01);
    // British adult men, 50th percentile (Pheasant & Haslegrave, Bodyspace, 3rd ed.): head length 195 mm,
    // breadth 155 mm. The scale is the geometric mean of the two single-measure scales.
    const double scale = std::sqrt((195.0 / length) * (155.0 / breadth));
    EXPECT_NEAR(scale, kScannedHeadMillimetresPerUnit, 0.1);
    // ... which puts both measures within one standard deviation (8 mm, 6 mm) of the population median.
    EXPECT_NEAR(length * kScannedHeadMillimetresPerUnit, 195.0, 8.0);
    EXPECT_NEAR(breadth * kScannedHeadMillimetresPerUnit, 155.0, 6.0);
}

// --- textures -----------------------------------------------------------------------------------------------

// The sRGB EOTF written out (IEC 61966-2-1), independent of OpenColorIO.
double srgbFormula(double encoded) {
    return encoded <= 0.04045 ? encoded / 12.92 : std::pow((encoded + 0.055) / 1.055, 2.4);
}

TEST(SrgbTransfer, KnownValuesThroughOpenColorIO) {
    // Published reference points of the sRGB curve; 2e-6: float evaluation of pow in OCIO's CPU path.
    EXPECT_NEAR(srgbToLinear(0.5f), 0.214041f, 2e-6f);
    EXPECT_NEAR(srgbToLinear(0.04045f), 0.0031308f, 2e-7f);
    EXPECT_NEAR(linearToSrgb(0.0031308f), 0.04045f, 2e-6f);
    EXPECT_NEAR(linearToSrgb(0.214041f), 0.5f, 2e-6f);
    EXPECT_EQ(srgbToLinear(0.0f), 0.0f);
    EXPECT_NEAR(srgbToLinear(1.0f), 1.0f, 1e-6f);
    // OpenColorIO makes the curve C1-continuous: its linear segment has slope 1 / 12.9232 up to 0.0392857
    // encoded (= offset / (gamma - 1)), where IEC 61966-2-1 rounds to 1 / 12.92 up to 0.04045. The two differ
    // by < 4e-7 in linear value; this pins OCIO's version.
    EXPECT_NEAR(srgbToLinear(0.02f), 0.02f / 12.9232f, 1e-8f) << "linear segment below the break point";
}

TEST(SrgbTransfer, MatchesTheFormulaAndRoundTrips) {
    double worstFormula = 0.0;
    double worstRoundTrip = 0.0;
    for (int i = 0; i <= 1000; ++i) {
        const float encoded = static_cast<float>(i) / 1000.0f;
        const float linear = srgbToLinear(encoded);
        worstFormula = std::max(worstFormula, std::abs(linear - srgbFormula(encoded)));
        worstRoundTrip = std::max(worstRoundTrip, static_cast<double>(std::abs(linearToSrgb(linear) - encoded)));
    }
    // 2e-6 absolute: single-precision evaluation of ((v + 0.055) / 1.055)^2.4 and its inverse.
    EXPECT_LT(worstFormula, 2e-6);
    EXPECT_LT(worstRoundTrip, 2e-6);
}

class TextureLoader : public InTempFolder {
protected:
    // Writes an 8-bit image with the given channel count; pixel values row-major, top row first.
    fs::path writeImage(const std::string& name, int width, int height, int channels,
                        const std::vector<unsigned char>& values) const {
        const fs::path path = folder_ / name;
        auto output = OIIO::ImageOutput::create(path.string());
        EXPECT_TRUE(output);
        OIIO::ImageSpec spec(width, height, channels, OIIO::TypeDesc::UINT8);
        EXPECT_TRUE(output->open(path.string(), spec));
        EXPECT_TRUE(output->write_image(OIIO::TypeDesc::UINT8, values.data()));
        output->close();
        return path;
    }
};

TEST_F(TextureLoader, DecodesSrgbColourAndLeavesDataAndAlphaAlone) {
    // 2 × 2 RGBA, top row first: (128, 64, 255, 128) (0, 10, 200, 255) / (255, 255, 255, 0) (1, 2, 3, 4)
    const fs::path path = writeImage("rgba.png", 2, 2, 4,
                                     {128, 64, 255, 128, 0, 10, 200, 255, //
                                      255, 255, 255, 0, 1, 2, 3, 4});
    const Image colour = loadTexture(path, ColorEncoding::sRGB);
    const Image data = loadTexture(path, ColorEncoding::Data);
    ASSERT_EQ(colour.width, 2);
    ASSERT_EQ(colour.height, 2);
    ASSERT_EQ(colour.pixels.size(), 16u);
    EXPECT_NEAR(data.texel(0, 0).r, 128.0f / 255.0f, 1e-6f);
    EXPECT_NEAR(data.texel(1, 0).b, 200.0f / 255.0f, 1e-6f);
    EXPECT_NEAR(data.texel(1, 1).a, 4.0f / 255.0f, 1e-6f) << "row order: the file's first row is row 0";
    for (int y = 0; y < 2; ++y) {
        for (int x = 0; x < 2; ++x) {
            for (int c = 0; c < 3; ++c) {
                EXPECT_NEAR(colour.texel(x, y)[c], srgbFormula(data.texel(x, y)[c]), 2e-6) << x << y << c;
            }
            EXPECT_EQ(colour.texel(x, y).a, data.texel(x, y).a) << "alpha is never colour-decoded";
        }
    }
    EXPECT_NEAR(colour.texel(0, 0).r, 0.2158605f, 2e-6f); // sRGB 128/255
}

TEST_F(TextureLoader, GreyAndRgbFilesBecomeRgba) {
    const Image grey = loadTexture(writeImage("grey.png", 1, 1, 1, {51}), ColorEncoding::Data);
    // 51 / 255 = 0.2; OpenImageIO's uint8 → float conversion may round the last bit differently.
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(grey.texel(0, 0)[c], 0.2f, 1e-7f);
    EXPECT_EQ(grey.texel(0, 0).a, 1.0f);
    const Image rgb = loadTexture(writeImage("rgb.jpg", 1, 1, 3, {255, 255, 255}), ColorEncoding::sRGB);
    EXPECT_NEAR(rgb.texel(0, 0).g, 1.0f, 1e-2f); // JPEG is lossy; white stays near white
    EXPECT_EQ(rgb.texel(0, 0).a, 1.0f);
}

TEST_F(TextureLoader, BadFilesNameThePath) {
    const fs::path missing = folder_ / "absent.png";
    EXPECT_EQ(expectInputError([&] { loadTexture(missing, ColorEncoding::sRGB); }),
              missing.string() + ": cannot read texture (no such file)");
    for (const char* name : {"garbage.png", "garbage.jpg", "garbage.exr", "garbage.unknown"}) {
        const fs::path path = write(name, "\x89PNG but not really, just garbage bytes \x01\x02");
        const std::string message = expectInputError([&] { loadTexture(path, ColorEncoding::Data); });
        EXPECT_EQ(message.rfind(path.string() + ": cannot read texture (", 0), 0u) << message;
        EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
}

TEST(ScannedHeadTextures, LoadAsLinearFloatRgba) {
    const char* assets = std::getenv("SKINLAB_ASSETS");
    if (assets == nullptr || *assets == '\0')
        GTEST_SKIP() << "SKINLAB_ASSETS is not set; needs the scanned head's maps";
    const fs::path folder = fs::path(assets) / "LeePerrySmith";
    const Image albedo = loadTexture(folder / "Map-COL.jpg", ColorEncoding::sRGB);
    const Image normals = loadTexture(folder / "Infinite-Level_02_Tangent_SmoothUV.jpg", ColorEncoding::Data);
    EXPECT_EQ(albedo.width, 1024);
    EXPECT_EQ(albedo.height, 1024);
    // Skin albedo is red-dominant on average; a tangent-space normal map averages to about (0.5, 0.5, 1).
    glm::dvec4 meanAlbedo(0.0);
    glm::dvec4 meanNormal(0.0);
    for (int y = 0; y < 1024; ++y) {
        for (int x = 0; x < 1024; ++x) {
            meanAlbedo += glm::dvec4(albedo.texel(x, y));
            meanNormal += glm::dvec4(normals.texel(x, y));
        }
    }
    meanAlbedo /= 1024.0 * 1024.0;
    meanNormal /= 1024.0 * 1024.0;
    EXPECT_GT(meanAlbedo.r, meanAlbedo.g);
    EXPECT_GT(meanAlbedo.g, meanAlbedo.b);
    EXPECT_LT(meanAlbedo.r, 0.8) << "decoded to linear: darker than the encoded values";
    EXPECT_NEAR(meanNormal.r, 0.5, 0.05);
    EXPECT_NEAR(meanNormal.g, 0.5, 0.05);
    EXPECT_GT(meanNormal.b, 0.9);
}

} // namespace
} // namespace skinlab::renderer
