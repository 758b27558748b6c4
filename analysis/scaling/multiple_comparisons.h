#pragma once
// Corrections for testing many pairs at once. Holm's step-down procedure (Holm 1979, Scand. J. Statist.
// 6:65) controls the family-wise error rate like Bonferroni under any dependence, and is uniformly more powerful.
// The family is all m(m−1)/2 pairs of one block.
#include <string>
#include <vector>

namespace skinlab::analysis::scaling {

enum class Correction { Holm, Bonferroni, None };
const char* correctionName(Correction correction);
Correction parseCorrection(const std::string& name); // throws InputError for anything else

// Adjusted p-values (reject when adjusted < α), in the input order.
std::vector<double> adjustPValues(const std::vector<double>& pValues, Correction correction);

} // namespace skinlab::analysis::scaling
