#pragma once
// What ShaderLibrary (shader_library.h) checks about the programs it links.
//
// Variants: every program variant the passes link is listed in shaderVariants(); ShaderLibrary::program refuses any
// other combination of stages and defines, and the test ShaderLibrary.EveryVariantCompilesAndLinks compiles and
// links each of them (EGL, label gl), so no variant goes unchecked. Each stage without defines is also validated at
// build time with glslangValidator (SKINLAB_VALIDATE_SHADERS).
//
// Line numbers: ShaderLibrary::source() marks an included file as GLSL source string N (its position among the
// includes, 1, 2, ...) from its line 1 and the including file as source string 0 from the line after the
// `#include`, so the driver's messages name the files' own lines; a compile error lists the source strings, e.g.
// `shader sss_blur.frag: compile failed (sources: 0 = sss_blur.frag, 1 = sss_extensions.glsl, ...): 0:160(5): ...`.
//
// Uniforms: a program's uniform locations are resolved once, when ShaderLibrary links it: every `uniform` its
// sources declare (in any variant) gets its location, -1 where this variant's linker removed it (a value set there
// is ignored, as GL does). setUniform() with a name the program's sources do not declare, or on a program
// ShaderLibrary did not link, is a bug: RuntimeError naming the uniform and the shaders.
#include "renderer/gl/shader_library.h"

#include <string>
#include <vector>

namespace skinlab::renderer::gl {

// One program the renderer links: its two stages and its defines, in the order the pass gives them.
struct ShaderVariant {
    std::string vertex;
    std::string fragment;
    ShaderDefines defines;
};

// Every program variant the passes link.
const std::vector<ShaderVariant>& shaderVariants();

// The location of `name` in `program` (-1: declared, but removed by the linker of this variant); an element of a
// declared array ("lightType[2]") is resolved on first use. Throws RuntimeError as above.
GLint uniformLocation(GLuint program, const char* name);

} // namespace skinlab::renderer::gl
