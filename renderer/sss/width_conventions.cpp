#include "renderer/sss/width_conventions.h"

namespace skinlab::renderer::sss {

double widthMmFromDemoSssWidth(double sssWidth, double mmPerUnit) {
    return kDemoEdgePerSssWidth * sssWidth * mmPerUnit;
}

double widthMmFromThesisSssWidth(double sssWidth, double mmPerUnit, ThesisBlurShader shader) {
    switch (shader) {
    case ThesisBlurShader::Separable: return kThesisSeparableEdgePerSssWidth * sssWidth * mmPerUnit;
    case ThesisBlurShader::GaussianSum: return kThesisGaussianSumEdgePerSssWidth * sssWidth * mmPerUnit;
    }
    return 0.0; // unreachable: every enumerator is handled above
}

} // namespace skinlab::renderer::sss
