#pragma once
// The pscbf method's own [sss] key as its typed parameters (declared in pscbf.cpp).
#include "renderer/sss/pscbf_kernel.h"
#include "renderer/sss/sss_params.h"

namespace skinlab::renderer::sss {

struct PscbfParams {
    PscbfSigma sigma = PscbfSigma::Variance; // sss.pscbf_sigma: how Table 1's 2.3 / 1.4 / 1.1 are read (pscbf_kernel.h)
};

// The pscbf keys of `params` (the defaults above for a parameter set of another method).
PscbfParams pscbfParams(const SssParams& params);

} // namespace skinlab::renderer::sss
