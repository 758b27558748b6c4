#include "analysis/scaling/multiple_comparisons.h"

#include "common/error.h"

#include <algorithm>
#include <numeric>

namespace skinlab::analysis::scaling {

const char* correctionName(Correction correction) {
    switch (correction) {
    case Correction::Holm: return "holm";
    case Correction::Bonferroni: return "bonferroni";
    case Correction::None: return "none";
    }
    return "holm";
}

Correction parseCorrection(const std::string& name) {
    if (name == "holm") return Correction::Holm;
    if (name == "bonferroni") return Correction::Bonferroni;
    if (name == "none") return Correction::None;
    throwInput("--correction", "", "'" + name + "' is not one of holm, bonferroni, none");
}

std::vector<double> adjustPValues(const std::vector<double>& pValues, Correction correction) {
    const size_t count = pValues.size();
    std::vector<double> adjusted(pValues);
    if (correction == Correction::None || count == 0) return adjusted;
    if (correction == Correction::Bonferroni) {
        for (double& p : adjusted) p = std::min(1.0, p * static_cast<double>(count));
        return adjusted;
    }
    // Holm: sort ascending, p_(k) · (count − k), running maximum so adjusted values keep the order.
    std::vector<size_t> order(count);
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return pValues[a] < pValues[b]; });
    double running = 0.0;
    for (size_t rank = 0; rank < count; ++rank) {
        const double value = std::min(1.0, pValues[order[rank]] * static_cast<double>(count - rank));
        running = std::max(running, value);
        adjusted[order[rank]] = running;
    }
    return adjusted;
}

} // namespace skinlab::analysis::scaling
