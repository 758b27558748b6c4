#version 450 core
// Background: where no geometry was drawn (depth still at the far plane), the environment's radiance seen
// along the pixel's view ray, or a constant colour; written into the diffuse buffer with mask 0 (the SSS stage
// copies non-skin pixels through). Equirectangular mapping of renderer/scene/environment.h:
//   u = 0.5 + atan(d.x, -d.z) / (2 pi),  v = acos(d.y) / pi,  v = 0 at the top row.
in vec2 texCoord;
layout(location = 0) out vec4 outDiffuse;

uniform int useEnvironment;
uniform vec3 backgroundColor;        // radiance when useEnvironment == 0
uniform float environmentIntensity;
uniform float exposure;
uniform mat4 inverseViewProjection;  // clip → world
uniform vec3 cameraPosition;
uniform mat3 environmentFromWorld;
layout(binding = 0) uniform sampler2D environmentMap;

void main() {
    if (useEnvironment == 0) {
        outDiffuse = vec4(exposure * backgroundColor, 0.0);
        return;
    }
    vec4 farPoint = inverseViewProjection * vec4(texCoord * 2.0 - 1.0, 1.0, 1.0);
    vec3 direction = environmentFromWorld * normalize(farPoint.xyz / farPoint.w - cameraPosition);
    const float pi = 3.14159265358979;
    vec2 uv = vec2(0.5 + atan(direction.x, -direction.z) / (2.0 * pi), acos(clamp(direction.y, -1.0, 1.0)) / pi);
    // textureLod 0: no mipmaps, and the u seam (atan's jump) must not select a coarse level.
    outDiffuse = vec4(exposure * environmentIntensity * textureLod(environmentMap, uv, 0.0).rgb, 0.0);
}
