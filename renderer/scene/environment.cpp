#include "renderer/scene/environment.h"

#include "common/error.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

namespace skinlab::renderer {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;

[[noreturn]] void failEnvironment(const std::filesystem::path& path, const std::string& why) {
    std::string message = why;
    std::replace(message.begin(), message.end(), '\n', ' '); // keep the error on one line
    throw InputError(path.string() + ": cannot read environment (" + message + ")");
}

} // namespace

glm::vec3 equirectDirection(float u, float v) {
    const float theta = kPi * v;               // polar angle from +Y
    const float phi = 2.0f * kPi * (u - 0.5f); // 0 at the image centre (-Z), +pi/2 at +X
    const float sinTheta = std::sin(theta);
    return {sinTheta * std::sin(phi), std::cos(theta), -sinTheta * std::cos(phi)};
}

glm::vec2 equirectCoordinates(const glm::vec3& direction) {
    const glm::vec3 d = glm::normalize(direction);
    const float u = 0.5f + std::atan2(d.x, -d.z) / (2.0f * kPi);
    const float v = std::acos(std::clamp(d.y, -1.0f, 1.0f)) / kPi;
    return {u, v};
}

glm::vec3 Environment::radiance(const glm::vec3& direction) const {
    const glm::vec2 uv = equirectCoordinates(direction);
    // Texel centres sit at (x + 0.5) / W; u wraps around, v clamps at the poles.
    const float x = uv.x * static_cast<float>(width) - 0.5f;
    const float y = std::clamp(uv.y * static_cast<float>(height) - 0.5f, 0.0f, static_cast<float>(height - 1));
    const float x0f = std::floor(x);
    const float y0f = std::floor(y);
    const float fx = x - x0f;
    const float fy = y - y0f;
    const auto wrap = [this](int column) { return ((column % width) + width) % width; };
    const int x0 = wrap(static_cast<int>(x0f));
    const int x1 = wrap(static_cast<int>(x0f) + 1);
    const int y0 = static_cast<int>(y0f);
    const int y1 = std::min(y0 + 1, height - 1);
    const glm::vec3 top = glm::mix(texel(x0, y0), texel(x1, y0), fx);
    const glm::vec3 bottom = glm::mix(texel(x0, y1), texel(x1, y1), fx);
    return glm::mix(top, bottom, fy);
}

Environment loadEnvironment(const std::filesystem::path& path) {
    std::error_code code;
    if (!std::filesystem::is_regular_file(path, code)) failEnvironment(path, "no such file");
    auto input = OIIO::ImageInput::open(path.string());
    if (!input) failEnvironment(path, OIIO::geterror());
    const OIIO::ImageSpec& spec = input->spec();
    const int channels = spec.nchannels;
    if (spec.width <= 0 || spec.height <= 0 || channels <= 0) failEnvironment(path, "empty image");
    if (std::abs(spec.width - 2 * spec.height) > 1) {
        failEnvironment(path, "not equirectangular: " + std::to_string(spec.width) + "x" + std::to_string(spec.height) +
                                  ", expected width = 2 * height");
    }
    std::vector<float> raw(static_cast<std::size_t>(spec.width) * static_cast<std::size_t>(spec.height) *
                           static_cast<std::size_t>(channels));
    // Radiance .hdr and OpenEXR are linear float radiance already; no colour decoding.
    if (!input->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, raw.data())) {
        failEnvironment(path, input->geterror());
    }
    input->close();

    Environment environment;
    environment.width = spec.width;
    environment.height = spec.height;
    const std::size_t pixelCount = static_cast<std::size_t>(spec.width) * static_cast<std::size_t>(spec.height);
    environment.pixels.resize(pixelCount);
    const bool grey = channels < 3;
    for (std::size_t i = 0; i < pixelCount; ++i) {
        const float* source = &raw[i * static_cast<std::size_t>(channels)];
        environment.pixels[i] = grey ? glm::vec3(source[0]) : glm::vec3(source[0], source[1], source[2]);
        if (!std::isfinite(environment.pixels[i].x) || !std::isfinite(environment.pixels[i].y) ||
            !std::isfinite(environment.pixels[i].z)) {
            failEnvironment(path, "non-finite radiance at pixel (" +
                                      std::to_string(i % static_cast<std::size_t>(spec.width)) + ", " +
                                      std::to_string(i / static_cast<std::size_t>(spec.width)) + ")");
        }
    }
    return environment;
}

Environment makeConstantEnvironment(const glm::vec3& radiance, int width, int height) {
    if (width < 1 || height < 1) throw InputError("constant environment: size must be at least 1x1");
    Environment environment;
    environment.width = width;
    environment.height = height;
    environment.pixels.assign(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), radiance);
    return environment;
}

std::array<float, 9> shBasis9(const glm::vec3& d) {
    // Real SH normalisation constants (R&H 2001, Eq. 3).
    constexpr float c0 = 0.282095f; // sqrt(1 / 4pi)
    constexpr float c1 = 0.488603f; // sqrt(3 / 4pi)
    constexpr float c2 = 1.092548f; // sqrt(15 / 4pi)
    constexpr float c3 = 0.315392f; // sqrt(5 / 16pi)
    constexpr float c4 = 0.546274f; // sqrt(15 / 16pi)
    return {c0,
            c1 * d.y,
            c1 * d.z,
            c1 * d.x,
            c2 * d.x * d.y,
            c2 * d.y * d.z,
            c3 * (3.0f * d.z * d.z - 1.0f),
            c2 * d.x * d.z,
            c4 * (d.x * d.x - d.y * d.y)};
}

std::array<glm::vec3, 9> projectSH9(const Environment& environment) {
    // Accumulate in double: a 2k environment sums millions of terms.
    std::array<glm::dvec3, 9> sums{};
    const int width = environment.width;
    const int height = environment.height;
    const double texelWidth = 2.0 * std::numbers::pi / width; // Δφ of one column
    for (int y = 0; y < height; ++y) {
        // Exact solid angle of a texel of this row: Δφ · (cos θ_top − cos θ_bottom); summed over the whole
        // image this is exactly 4π (a sin θ · Δθ approximation is not, near the poles).
        const double thetaTop = std::numbers::pi * y / height;
        const double thetaBottom = std::numbers::pi * (y + 1) / height;
        const double solidAngle = texelWidth * (std::cos(thetaTop) - std::cos(thetaBottom));
        const float v = (static_cast<float>(y) + 0.5f) / static_cast<float>(height);
        std::array<glm::dvec3, 9> rowSums{};
        for (int x = 0; x < width; ++x) {
            const float u = (static_cast<float>(x) + 0.5f) / static_cast<float>(width);
            const std::array<float, 9> basis = shBasis9(equirectDirection(u, v));
            const glm::dvec3 radiance(environment.texel(x, y));
            for (int i = 0; i < 9; ++i) rowSums[i] += radiance * static_cast<double>(basis[i]);
        }
        for (int i = 0; i < 9; ++i) sums[i] += rowSums[i] * solidAngle;
    }
    std::array<glm::vec3, 9> coefficients{};
    for (int i = 0; i < 9; ++i) coefficients[i] = glm::vec3(sums[i]);
    return coefficients;
}

std::array<glm::vec3, 9> irradianceCoefficientsSH9(const std::array<glm::vec3, 9>& radianceCoefficients) {
    // Clamped-cosine convolution in the SH domain (R&H 2001, Eq. 8): Â_0 = π, Â_1 = 2π/3, Â_2 = π/4.
    constexpr float band0 = kPi;
    constexpr float band1 = 2.0f * kPi / 3.0f;
    constexpr float band2 = kPi / 4.0f;
    constexpr std::array<float, 9> bandFactor = {band0, band1, band1, band1, band2, band2, band2, band2, band2};
    std::array<glm::vec3, 9> result{};
    for (int i = 0; i < 9; ++i) result[i] = bandFactor[i] * radianceCoefficients[i];
    return result;
}

glm::vec3 irradianceSH9(const std::array<glm::vec3, 9>& radianceCoefficients, const glm::vec3& normal) {
    const std::array<glm::vec3, 9> coefficients = irradianceCoefficientsSH9(radianceCoefficients);
    const std::array<float, 9> basis = shBasis9(glm::normalize(normal));
    glm::vec3 irradiance(0.0f);
    for (int i = 0; i < 9; ++i) irradiance += coefficients[i] * basis[i];
    return irradiance;
}

Environment irradianceMap(const Environment& environment, int width, int height) {
    // Radiance averaged over blocks of texels (weighted by solid angle) to at most 2·width × 2·height.
    const int coarseWidth = std::min(environment.width, 2 * width);
    const int coarseHeight = std::min(environment.height, 2 * height);
    const auto rowSolidAngle = [](int y, int rows, int columns) {
        return 2.0 * std::numbers::pi / columns *
               (std::cos(std::numbers::pi * y / rows) - std::cos(std::numbers::pi * (y + 1) / rows));
    };
    std::vector<glm::dvec3> sums(static_cast<std::size_t>(coarseWidth) * coarseHeight, glm::dvec3(0.0));
    for (int y = 0; y < environment.height; ++y) {
        const int cy = y * coarseHeight / environment.height;
        const double solidAngle = rowSolidAngle(y, environment.height, environment.width);
        for (int x = 0; x < environment.width; ++x)
            sums[static_cast<std::size_t>(cy) * coarseWidth + x * coarseWidth / environment.width] +=
                glm::dvec3(environment.texel(x, y)) * solidAngle;
    }
    // Each coarse texel: its radiance times its solid angle (the blocks' sums), at its centre direction.
    struct Source {
        glm::dvec3 direction;
        glm::dvec3 power;
    };
    std::vector<Source> sources;
    sources.reserve(sums.size());
    for (int y = 0; y < coarseHeight; ++y)
        for (int x = 0; x < coarseWidth; ++x) {
            const glm::dvec3& power = sums[static_cast<std::size_t>(y) * coarseWidth + x];
            if (power == glm::dvec3(0.0)) continue;
            sources.push_back({glm::dvec3(equirectDirection((static_cast<float>(x) + 0.5f) / coarseWidth,
                                                            (static_cast<float>(y) + 0.5f) / coarseHeight)),
                               power});
        }
    Environment map;
    map.width = width;
    map.height = height;
    map.pixels.resize(static_cast<std::size_t>(width) * height);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const glm::dvec3 normal(equirectDirection((static_cast<float>(x) + 0.5f) / static_cast<float>(width),
                                                      (static_cast<float>(y) + 0.5f) / static_cast<float>(height)));
            glm::dvec3 irradiance(0.0);
            for (const Source& source : sources) {
                const double cosine = glm::dot(normal, source.direction);
                if (cosine > 0.0) irradiance += source.power * cosine;
            }
            map.pixels[static_cast<std::size_t>(y) * width + x] = glm::vec3(irradiance);
        }
    return map;
}

} // namespace skinlab::renderer
