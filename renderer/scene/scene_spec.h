#pragma once
// The strict scene spec (TOML): what to render, how it is lit, seen and displayed. docs/scenes.md lists every
// key with its unit and range. Specs come from a file or from a built-in scene (builtin_scenes.h); either way
// `--set key=value` overrides are applied to the TOML before it is read, and an unknown key, a wrong type or an
// out-of-range value throws InputError naming the file and the key.
//
// Paths in a spec: "assets:REL" is REL under the assets folder (--assets DIR or $SKINLAB_ASSETS); any other
// relative path is relative to the spec file's folder.
#include "renderer/sss/eevee_params.h"
#include "renderer/sss/pathtraced_params.h"
#include "renderer/sss/skin_model.h"
#include "renderer/sss/sss_params.h"

#include <array>
#include <filesystem>
#include <glm/glm.hpp>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace skinlab::renderer {

struct CameraSpec {
    std::string view = "mid";    // close | mid | far | explicit
    double fovDeg = 30.0;        // vertical field of view, degrees
    double yawDeg = 0.0;         // named views: orbit about +Y (positive: camera moves towards +X)
    double pitchDeg = 0.0;       // named views: orbit upwards (positive: camera above the target)
    glm::vec3 position{0, 0, 1}; // explicit view, world units
    glm::vec3 target{0, 0, 0};   // explicit view, world units
    glm::vec3 up{0, 1, 0};       // explicit view
};

struct LightSpec {
    std::string type = "directional"; // directional | spot
    glm::vec3 direction{0, 0, -1};    // directional: the direction light travels (towards the scene)
    glm::vec3 position{0, 0, 1};      // spot: world units
    glm::vec3 target{0, 0, 0};        // spot: the point it aims at; intensity is specified there
    glm::vec3 color{1, 1, 1};         // linear Rec.709 multiplier
    // Outgoing radiance of a white Lambertian surface facing the light (directional: anywhere; spot: at the
    // target distance, inverse-square elsewhere) = irradiance / π. The thesis' "light colour" L_c.
    double intensity = 1.0;
    bool shadow = true;
    double innerAngleDeg = 20.0; // spot: full intensity inside this half-angle
    double outerAngleDeg = 30.0; // spot: zero outside this half-angle (smooth in between)
};

struct MaterialSpec {
    std::string name;                // a material of the model, or "*" for all
    std::optional<glm::vec3> albedo; // linear; multiplies the albedo texture and vertex colours
    std::optional<bool> skin;
    std::optional<double> glossiness;        // s in [0, 1]: thesis Eq. 4.5, alpha = 8192 s^5
    std::optional<double> specularIntensity; // multiplies the specular lobe (and the specular map)
};

struct TexturesSpec {
    std::filesystem::path albedo;    // colour, sRGB-encoded; empty: none
    std::filesystem::path normal;    // tangent-space normal map (data)
    std::filesystem::path specular;  // specular intensity map (data, red channel)
    std::filesystem::path occlusion; // ambient occlusion map (data, red channel), multiplies IBL
    std::filesystem::path skinMask;  // skin mask (data, red channel), multiplies the material's skin flag
    double normalStrength = 1.0;     // 0: geometric normal, 1: the map as authored
};

struct EnvironmentSpec {
    std::filesystem::path file;             // equirectangular HDR; empty: constant radiance
    glm::vec3 radiance{0, 0, 0};            // constant environment radiance when no file
    double intensity = 1.0;                 // multiplies the environment (lighting and background)
    double rotationDeg = 0.0;               // about +Y
    std::string background = "environment"; // environment | color
    glm::vec3 backgroundColor{0, 0, 0};     // radiance when background = color
    // The rasterizer's diffuse environment light: "sh9" — 9 spherical-harmonic coefficients (R&H 2001; exact for a
    // constant environment and a sky over black); "exact" — the cosine integral itself, tabulated by normal
    // (irradianceMap), as a path tracer integrates it.
    std::string irradiance = "sh9";
};

// render.ssaa_factor: its default (samples per pixel along each axis) and range; the internal size (image size ×
// factor) stays within kMaxInternalSize, the texture size every GL 4.5 driver the project meets supports (Mesa
// llvmpipe: 16384).
inline constexpr int kDefaultSsaaFactor = 2;
inline constexpr int kMaxSsaaFactor = 8;
inline constexpr int kMaxInternalSize = 16384;
// EEVEE's pixel filter with render.antialiasing = "ssaa" (render.filter_size, px). EEVEE (Blender 2.8–4.1) jitters
// its temporal samples by a Blackman-Harris window of full width 2 × filter_size px (the inverse CDF of the window
// on [−0.5, 0.5] scaled by 4, in NDC, i.e. ±filter_size px), whose standard deviation is 0.1385 × its full width;
// it has no box filter. 1.042 px gives the standard deviation of a box of one pixel, 1/√12 px.
inline constexpr double kEeveeBoxMatchedFilterPx = 1.042;
// A window of the camera's frame (render.window): pixels of the render.width × render.height frame, x from the
// left, y from the top row. Only the window is rendered, at the frame's pixel scale (an off-axis projection of the
// same camera): the image is the frame's pixels inside the window, not a resampling.
struct RenderWindow {
    int x = 0;
    int y = 0;
    int width = 0;
    int height = 0;
};

struct SceneSpec {
    std::string source;        // spec path or builtin:NAME, as given
    std::string modelSource;   // "builtin:NAME" or the model file path (resolved)
    double depthGapMm = 200.0; // builtin:halo only
    double thicknessMm = 2.5;  // builtin:ear only
    bool skinDetail = true;    // builtin:head only: its procedural skin maps (skin_detail.h)
    bool flipV = false;        // model files whose UVs are upside down (v = 1 - v), e.g. the scan
    double mmPerUnit = 1.0;
    TexturesSpec textures;
    std::vector<MaterialSpec> materials;
    CameraSpec camera;
    std::vector<LightSpec> lights;
    int shadowResolution = 2048; // texels, square
    int shadowPcfRadius = 1;     // PCF taps: (2r+1)^2
    EnvironmentSpec environment;
    int width = 512; // the image rendered: the window's size with render.window, else the frame's
    int height = 512;
    int frameWidth = 512; // render.width, render.height: the camera's whole frame (f_px, aspect)
    int frameHeight = 512;
    std::optional<RenderWindow> window; // render.window
    double exposureEv = 0.0;            // beauty and AOVs are scaled by 2^exposure_ev
    // render.antialiasing: "ssaa" renders every pass at ssaaFactor × (width, height) and resolves each layer to
    // (width, height) with a box of one output pixel (renderer/gl/resolve_pass.h); "none" (ssaaFactor 1) samples
    // each pixel's centre once.
    std::string antialiasing = "ssaa";
    int ssaaFactor = kDefaultSsaaFactor;    // samples per pixel along each axis; 1 when antialiasing = "none"
    std::string ssaaFilter = "box";         // the reconstruction filter: box (one output pixel, as Cycles' box)
    std::string toneMapper = "filmic";      // linear | exponential | reinhard | reinhard-rgb | filmic
    double exponentialK = 1.0;              // exponential: 1 - exp(-k x)
    double filmicWhite = 11.2;              // filmic (Hable 2010): linear value mapped to display white
    double reinhardKey = 0.18;              // reinhard (Reinhard et al. 2002, Eq. 2): the key a
    sss::SssParams sss;                     // [sss], typed; the method's keys only (sss::methodTable())
    sss::TransmittanceParams transmittance; // [transmittance], typed
    // [pathtraced], typed (renderer/sss/pathtraced_params.h); read for every scene, recorded in `resolved` only
    // when sss.method = "pathtraced" (the other methods do not depend on it).
    pathtraced::PathtracedParams pathtraced;
    // [eevee], typed (renderer/sss/eevee_params.h); recorded in `resolved` only when sss.method = "eevee".
    pathtraced::EeveeParams eevee;
    // [skin] (renderer/scene/skin_spec.h, docs/skin-tones.md): the tone and what the model derives from it; its
    // profile is also written into `sss` (SssParams::skinLobeWeights, skinShapeMm). Absent: the scene's own skin.
    std::optional<sss::SkinOptics> skin;

    nlohmann::json resolved; // every parameter after defaults and overrides
};

// Loads and validates a scene: `scene` is "builtin:NAME" or a TOML path; overrides are "key=value".
// `assetsDirectory` (may be empty) resolves "assets:" paths. Checks that referenced files exist.
SceneSpec loadSceneSpec(const std::string& scene, const std::vector<std::string>& overrides,
                        const std::filesystem::path& assetsDirectory);

// The camera of a scene, resolved against the model's bounds and the image aspect.
struct CameraPose {
    glm::vec3 position{0.0f};
    glm::vec3 target{0.0f};
    glm::vec3 up{0, 1, 0};
    float fovYRadians = 0.5f;
    float nearPlane = 0.01f; // world units
    float farPlane = 100.0f; // world units
    glm::mat4 view{1.0f};
    glm::mat4 projection{1.0f};
    float focalLengthPixels = 1.0f; // (frame height / 2) / tan(fovY / 2)
    // Where the view axis meets the image, in pixels of the rendered image (row 0 at the bottom): its centre, or
    // off it for a render.window.
    glm::vec2 principalPoint{0.0f};
};

// Named views look at the bounding sphere of the `frame` bounds (the skin parts of the model; all of it when
// it has no skin) from +Z, orbited by yaw/pitch: the sphere's silhouette fills 40 % of the image height for
// far, 90 % for mid and 180 % for close (the face fills the frame). Near/far planes enclose the bounding
// sphere of the whole scene's bounds.
// `width` × `height` is the whole frame; with a `window`, the projection is the off-axis one that maps exactly the
// window's pixels of that frame to the rendered image (focal length in pixels unchanged).
CameraPose frameCamera(const CameraSpec& camera, const glm::vec3& frameMin, const glm::vec3& frameMax,
                       const glm::vec3& sceneMin, const glm::vec3& sceneMax, int width, int height,
                       const std::optional<RenderWindow>& window = std::nullopt);

} // namespace skinlab::renderer
