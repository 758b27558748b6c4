#pragma once
// The textures of one frame and the framebuffers the passes draw into, (re)allocated when the size changes.
//   main pass:     diffuse, specular, albedo, linearDepth, normal, geometricNormal, mask, transmittance
//                  (+ depthBuffer)
//   background:    diffuse (+ depthBuffer, tested LEQUAL at the far plane)
//   surface AOVs:  linearDepth, geometricNormal, albedo, mask → aux, curvature
//   transmittance: diffuse += transmittance (× curvature option)
//   SSS stage:     diffuse (+ aux, curvature, albedo, depth, mask) → scatteredDiffuse
//   add specular:  scatteredDiffuse + specular → beauty
//   tone map:      beauty → display (linear display-referred, [0, 1])
#include "renderer/gl/gl_resources.h"

namespace skinlab::renderer::gl {

struct FrameTargets {
    int width = 0;
    int height = 0;
    Texture diffuse;          // GL_RGBA32F, a = mask
    Texture specular;         // GL_RGBA32F
    Texture albedo;           // GL_RGBA32F, a = mask
    Texture linearDepth;      // GL_R32F, world units, +inf on background
    Texture normal;           // GL_RGBA32F
    Texture geometricNormal;  // GL_RGBA32F
    Texture mask;             // GL_R32F
    Texture transmittance;    // GL_RGBA32F: rgb = light transmitted through thin parts (exposure applied), 0 if off
    Texture aux;              // GL_R32F: Mikkelsen's auxiliary image F (sss.cbf), 0 off skin
    Texture curvature;        // GL_R32F: smoothed curvature of the geometric surface, 1/world unit, ≥ 0
    Texture depthBuffer;      // GL_DEPTH_COMPONENT32F
    Texture scatteredDiffuse; // GL_RGBA32F
    Texture beauty;           // GL_RGBA32F
    Texture display;          // GL_RGBA32F
    Framebuffer mainFramebuffer;
    Framebuffer backgroundFramebuffer;
    Framebuffer beautyFramebuffer;
    Framebuffer displayFramebuffer;

    void resize(int newWidth, int newHeight);
    // Clears the main targets: colours 0, linear depth +inf, depth buffer 1.
    void clear();
};

// Reads a texture's level 0 as floats, top row first (GL rows are bottom first), `channels` of GL_RED/RG/RGB/RGBA.
void readTexture(GLuint texture, int width, int height, int channels, float* out);

} // namespace skinlab::renderer::gl
