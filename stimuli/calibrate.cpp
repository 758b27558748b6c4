#include "stimuli/calibrate.h"

#include "analysis/metrics/cvvdp.h"
#include "analysis/metrics/metric_render.h"
#include "common/error.h"
#include "renderer/renderer.h"
#include "stimuli/build.h"
#include "stimuli/presentation.h"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <spdlog/spdlog.h>

namespace skinlab::stimuli {

namespace fs = std::filesystem;

namespace {

std::string number(double v, const char* format = "%.3g") {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, format, v);
    return buffer;
}

// The search's arguments checked (InputError naming the option); a whole-number range rounded inwards.
LevelSearch checkedSearch(const LevelSearch& search, const std::vector<double>& targets) {
    LevelSearch checked = search;
    double& lo = checked.lo;
    double& hi = checked.hi;
    if (!std::isfinite(lo) || !std::isfinite(hi) || !(lo < hi))
        throwInput("--range", "", number(lo, "%g") + "," + number(hi, "%g") + ": LO must be below HI (finite numbers)");
    if (search.integral) {
        lo = std::ceil(lo);
        hi = std::floor(hi);
        if (!(lo < hi))
            throwInput("--range", "",
                       number(search.lo, "%g") + "," + number(search.hi, "%g") +
                           ": holds fewer than two whole numbers (the parameter is an integer)");
    }
    if (!std::isfinite(search.tolerance) || !(search.tolerance > 0.0))
        throwInput("--tolerance", "", number(search.tolerance, "%g") + " must be a positive number of JOD");
    if (search.maxProbes < 1)
        throwInput("--max-probes", "", std::to_string(search.maxProbes) + " must be a positive number");
    if (targets.empty()) throwInput("--target-jod", "", "no target given");
    for (double t : targets)
        if (!std::isfinite(t) || !(t > 0.0))
            throwInput("--target-jod", "", number(t, "%g") + " must be a positive number of JOD (a difference)");
        else if (t <= search.tolerance)
            throwInput("--target-jod", "",
                       number(t, "%g") + " is within the tolerance " + number(search.tolerance, "%g") +
                           " of no difference (the reference itself would meet it)");

    return checked;
}

} // namespace

std::string levelText(double value, bool integral) {
    if (integral) return std::to_string(static_cast<long long>(std::llround(value)));
    char buffer[64];
    auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, value);
    std::string text(buffer, ec == std::errc() ? end : buffer);
    if (text.find_first_of(".eEn") == std::string::npos) text += ".0"; // a TOML float, not an integer
    return text;
}

LevelSearchResult searchLevels(const std::function<double(double)>& predictedJod, const std::vector<double>& targets,
                               const LevelSearch& given) {
    const LevelSearch search = checkedSearch(given, targets);
    const double lo = search.lo, hi = search.hi;
    const double tol = search.tolerance;
    LevelSearchResult result;
    std::map<double, double> seen; // value → difference (10 − predicted JOD)
    auto difference = [&](double v, int* renders) {
        if (auto it = seen.find(v); it != seen.end()) return it->second;
        const double d = 10.0 - predictedJod(v);
        if (!std::isfinite(d)) throw RuntimeError("the prediction at " + number(v, "%g") + " is not a number");
        seen[v] = d;
        ++result.predictions;
        if (renders) ++*renders;
        return d;
    };
    result.differenceAtLo = difference(lo, nullptr);
    result.differenceAtHi = difference(hi, nullptr);
    const double dLo = result.differenceAtLo, dHi = result.differenceAtHi;
    if (std::abs(dHi - dLo) <= tol)
        result.warnings.push_back("the predicted difference changes by only " + number(std::abs(dHi - dLo)) +
                                  " JOD over [" + number(lo, "%g") + ", " + number(hi, "%g") +
                                  "]: the parameter barely changes the image");
    const bool increasing = dHi >= dLo;
    const double sign = increasing ? 1.0 : -1.0; // f = sign·difference is non-decreasing from lo to hi
    const std::string ends = "the difference is " + number(dLo) + " JOD at " + number(lo, "%g") + " and " +
                             number(dHi) + " JOD at " + number(hi, "%g");

    for (double target : targets) {
        CalibratedLevel level;
        level.targetJod = target;
        auto closest = [&] { // ties: the smallest value
            level.value = level.achievedJod = std::numeric_limits<double>::quiet_NaN();
            for (const auto& [v, d] : seen)
                if (std::isnan(level.value) || std::abs(d - target) < std::abs(level.achievedJod - target)) {
                    level.value = v;
                    level.achievedJod = d;
                }
        };
        auto finish = [&] {
            closest();
            level.reached = std::abs(level.achievedJod - target) <= tol;
            result.levels.push_back(level);
        };
        closest();
        if (std::abs(level.achievedJod - target) <= tol) {
            finish();
            continue;
        }
        if (target < std::min(dLo, dHi) || target > std::max(dLo, dHi)) {
            level.note = "unreachable in [" + number(lo, "%g") + ", " + number(hi, "%g") + "]: " + ends;
            finish();
            continue;
        }
        // The tightest bracket the earlier probes give: adjacent values around the target.
        const double tau = sign * target;
        double a = lo, b = hi;
        for (auto it = seen.begin(); std::next(it) != seen.end(); ++it) {
            auto next = std::next(it);
            if (sign * it->second < tau && sign * next->second > tau) {
                a = it->first;
                b = next->first;
                break;
            }
        }
        int probes = 0;
        while (true) {
            const double fa = sign * seen.at(a), fb = sign * seen.at(b);
            if (probes >= search.maxProbes) {
                level.note = "not within " + number(tol, "%g") + " JOD after " + std::to_string(probes) + " probes";
                break;
            }
            // Rounded to 12 significant digits, so that the level written (shortest round trip) reads as the
            // binary fraction of the range it is, not as 0.6898437499999999.
            double mid = std::stod(number(0.5 * (a + b), "%.12g"));
            if (search.integral) {
                if (b - a <= 1.0) {
                    level.note = "the difference jumps from " + number(seen.at(a)) + " JOD at " + number(a, "%g") +
                                 " to " + number(seen.at(b)) + " JOD at " + number(b, "%g") + " (whole numbers only)";
                    break;
                }
                mid = std::floor(mid);
            } else if (!(mid > a && mid < b) || b - a <= 1e-9 * (hi - lo)) {
                level.note = "the difference jumps from " + number(seen.at(a)) + " to " + number(seen.at(b)) +
                             " JOD near " + number(mid, "%g");
                break;
            }
            const double d = difference(mid, &level.renders);
            ++probes;
            const double fm = sign * d;
            if (fm < std::min(fa, fb) - tol || fm > std::max(fa, fb) + tol)
                result.warnings.push_back("not monotone: the difference is " + number(d) + " JOD at " +
                                          number(mid, "%g") + ", outside the " + number(seen.at(a)) + " .. " +
                                          number(seen.at(b)) + " JOD at " + number(a, "%g") + " and " +
                                          number(b, "%g"));
            if (std::abs(d - target) <= tol) break;
            (fm < tau ? a : b) = mid;
        }
        finish();
    }
    return result;
}

namespace {

// A temporary folder removed with everything in it when the calibration ends.
class TemporaryFolder {
public:
    TemporaryFolder() {
        std::string pattern = (fs::temp_directory_path() / "skinlab-calibrate-XXXXXX").string();
        if (!::mkdtemp(pattern.data())) throw RuntimeError("cannot create a temporary folder " + pattern);
        path_ = pattern;
    }
    ~TemporaryFolder() {
        std::error_code ignored;
        fs::remove_all(path_, ignored);
    }
    TemporaryFolder(const TemporaryFolder&) = delete;
    TemporaryFolder& operator=(const TemporaryFolder&) = delete;
    const fs::path& path() const { return path_; }

private:
    fs::path path_;
};

std::string keyOf(const std::string& override) { return override.substr(0, override.find('=')); }

bool keysOverlap(const std::string& a, const std::string& b) {
    const std::string& shorter = a.size() < b.size() ? a : b;
    const std::string& longer = a.size() < b.size() ? b : a;
    return longer.compare(0, shorter.size(), shorter) == 0 &&
           (longer.size() == shorter.size() || longer[shorter.size()] == '.');
}

std::string pointerOf(const std::string& key) {
    std::string pointer = "/" + key;
    std::replace(pointer.begin(), pointer.end(), '.', '/');
    return pointer;
}

renderer::RenderRequest requestOf(const Stimulus& stimulus, const std::vector<std::string>& overrides,
                                  const fs::path& assets) {
    renderer::RenderRequest request;
    request.scene = stimulus.scene;
    request.overrides = overrides;
    request.assetsDir = assets;
    return request;
}

// The scene key of --factor: a numeric key that no stimulus set holds fixed.
std::string calibratedKey(const std::string& factor) {
    if (factor.empty()) throwInput("--factor", "", "missing (a numeric scene key, e.g. sss.width_mm)");
    const std::string key = sceneKeyOf(factor);
    if (key.empty() || key == "sss.method" || key == "camera.view")
        throwInput("--factor", "", "'" + factor + "' is not a numeric scene key (e.g. sss.width_mm)");
    for (const auto& fixed : alwaysFixedKeys())
        if (keysOverlap(key, fixed))
            throwInput("--factor", "",
                       "'" + key + "' is held fixed across every stimulus set (" + fixed + "); it cannot vary");
    return key;
}

// The index in plan.all of the stimulus whose parameter varies (--stimulus, else the first that is no reference).
size_t baseStimulusIndex(const CalibrateOptions& options, const BuildPlan& plan) {
    const std::string& specName = plan.spec.fileName;
    const Stimulus* base = nullptr;
    size_t baseIndex = 0;
    for (size_t i = 0; i < plan.all.size(); ++i) {
        const Stimulus& s = plan.all[i];
        if (options.stimulus.empty() ? !s.reference : s.id == options.stimulus) {
            base = &s;
            baseIndex = i;
            break;
        }
    }
    if (!base && !options.stimulus.empty())
        throwInput("--stimulus", "", "'" + options.stimulus + "' is not a stimulus of " + specName);
    if (!base) throwInput(specName, "", "has no stimulus but references");
    if (base->reference)
        throwInput("--stimulus", "", "'" + base->id + "' is a [[reference]] stimulus; choose one it is compared with");
    return baseIndex;
}

// The search over the range (as given, else the smallest and largest numeric level of the spec's factor), checked
// with the reference level before anything renders.
LevelSearch calibrationSearch(const CalibrateOptions& options, const BuildPlan& plan, const std::string& key,
                              bool integral) {
    const std::string& specName = plan.spec.fileName;
    std::pair<double, double> range;
    if (options.range) {
        range = *options.range;
    } else {
        std::vector<double> levels;
        for (const auto& factor : plan.spec.factors)
            if (factor.key == key)
                for (const auto& level : factor.levels)
                    if (level.json.is_number()) levels.push_back(level.json.get<double>());
        if (levels.size() < 2)
            throwInput("--range", "", "missing (LO,HI; " + specName + " has no factor '" + key + "' to take it from)");
        range = {*std::min_element(levels.begin(), levels.end()), *std::max_element(levels.begin(), levels.end())};
    }
    LevelSearch search;
    search.lo = range.first;
    search.hi = range.second;
    search.tolerance = options.tolerance;
    search.maxProbes = options.maxProbes;
    search.integral = integral;
    search = checkedSearch(search, options.targets); // before anything renders
    if (options.referenceLevel) {
        const double v = *options.referenceLevel;
        if (!std::isfinite(v)) throwInput("--reference-level", "", "must be a finite number");
        if (v > range.first && v < range.second)
            throwInput("--reference-level", "",
                       number(v, "%g") + " lies inside the range " + number(range.first, "%g") + "," +
                           number(range.second, "%g") +
                           ": the difference grows on both sides of it; give a range on one side");
    }
    return search;
}

// The base stimulus with the calibrated key set to a value.
struct VariedStimulus {
    const Stimulus* base = nullptr;
    std::vector<std::string> baseOverrides; // without the calibrated key
    std::string key;
    bool integral = false;
    fs::path assets;

    std::vector<std::string> overridesAt(double v) const {
        std::vector<std::string> o = baseOverrides;
        o.push_back(key + "=" + levelText(v, integral));
        return o;
    }
    nlohmann::json resolveAt(double v, const std::string& option) const {
        try {
            return renderer::resolveScene(requestOf(*base, overridesAt(v), assets));
        } catch (const InputError& e) {
            throwInput(option, "", key + "=" + levelText(v, integral) + ": " + e.what());
        }
    }
};

// Both ends and the reference level must be valid values that change what is rendered.
void checkLevelsRender(const VariedStimulus& varied, const LevelSearch& search,
                       const std::optional<double>& referenceLevel) {
    const nlohmann::json resolvedLo = varied.resolveAt(search.lo, "--range");
    const nlohmann::json resolvedHi = varied.resolveAt(search.hi, "--range");
    if (referenceLevel) varied.resolveAt(*referenceLevel, "--reference-level");
    if (resolvedLo == resolvedHi)
        throwInput("--factor", "",
                   "'" + varied.key + "' does not change stimulus '" + varied.base->id +
                       "' (its method does not read it?)");
}

// What the varied stimulus is compared with: itself at --reference-level, else its block's [[reference]]; its name
// goes into report.reference.
std::pair<const Stimulus*, std::vector<std::string>> calibrationReference(const CalibrateOptions& options,
                                                                          const BuildPlan& plan, size_t baseIndex,
                                                                          const VariedStimulus& varied,
                                                                          CalibrationReport& report) {
    const Stimulus* base = varied.base;
    std::vector<std::string> referenceOverrides;
    const Stimulus* referenceStimulus = &plan.all[baseIndex];
    if (options.referenceLevel) {
        referenceOverrides = varied.overridesAt(*options.referenceLevel);
        report.reference = varied.key + "=" + levelText(*options.referenceLevel, report.integral);
    } else {
        referenceStimulus = nullptr;
        for (const auto& s : plan.all)
            if (s.reference && s.block == base->block) {
                referenceStimulus = &s;
                break;
            }
        if (!referenceStimulus)
            throwInput("--reference-level", "",
                       "missing: " + plan.spec.fileName + " has no [[reference]] in the block '" + base->block +
                           "' of stimulus '" + base->id + "'");
        referenceOverrides = referenceStimulus->overrides;
        report.reference = referenceStimulus->id;
    }
    return {referenceStimulus, referenceOverrides};
}

} // namespace

CalibrationReport calibrateLevels(const CalibrateOptions& options) {
    const auto start = std::chrono::steady_clock::now();
    const std::string key = calibratedKey(options.factor);
    const metrics::CvvdpDisplay& display = options.display;

    BuildPlan plan = planBuild(options.spec, options.specOverrides, std::nullopt, options.assetsDir);
    const std::string& specName = plan.spec.fileName;
    for (const auto& fixed : plan.spec.fixed)
        if (keysOverlap(key, fixed.key))
            throwInput("--factor", "",
                       "'" + key + "' is the fixed parameter fixed." + fixed.key + " of " + specName +
                           "; remove it from [fixed] to calibrate it");

    // The stimulus whose parameter varies, and its reference.
    const size_t baseIndex = baseStimulusIndex(options, plan);
    const Stimulus* base = &plan.all[baseIndex];

    CalibrationReport report;
    report.set = plan.spec.name;
    report.factor = options.factor;
    report.key = key;
    report.stimulus = base->id;
    report.display = metrics::describeCvvdpDisplay(display);

    // The base stimulus' overrides without the calibrated key (a factor of the set, or an include's extra key).
    VariedStimulus varied;
    varied.base = base;
    varied.key = key;
    varied.assets = options.assetsDir;
    for (const auto& o : base->overrides)
        if (!keysOverlap(keyOf(o), key)) varied.baseOverrides.push_back(o);
    const nlohmann::json resolvedBase = plan.resolved[baseIndex];
    const nlohmann::json::json_pointer pointer(pointerOf(key));
    if (!resolvedBase.contains(pointer) || !resolvedBase.at(pointer).is_number())
        throwInput("--factor", "",
                   "'" + key + "' is not a parameter holding one number in stimulus '" + base->id +
                       "' (see docs/scenes.md)");
    report.integral = resolvedBase.at(pointer).is_number_integer();
    varied.integral = report.integral;

    report.search = calibrationSearch(options, plan, key, report.integral);
    checkLevelsRender(varied, report.search, options.referenceLevel);
    const auto [referenceStimulus, referenceOverrides] = calibrationReference(options, plan, baseIndex, varied, report);

    // Rendering: the set's machinery (scene, fixed parameters, overrides) into a temporary folder; the display
    // PNG (what an observer sees) decoded to linear light.
    TemporaryFolder folder;
    renderer::Renderer renderer;
    int renders = 0;
    const auto [frameWidth, frameHeight] = presentationFrame(*base, plan.resolved[baseIndex]);
    auto render = [&](const Stimulus& stimulus, std::vector<std::string> overrides) {
        // Presented like the set presents it: a native presentation renders the crop's window (presentation.h).
        const std::vector<std::string> native = nativeRenderOverrides(stimulus.presentation, frameWidth, frameHeight);
        overrides.insert(overrides.end(), native.begin(), native.end());
        renderer::RenderRequest request = requestOf(stimulus, overrides, options.assetsDir);
        const std::string name = "render-" + std::to_string(renders + 1);
        request.exrPath = folder.path() / (name + ".exr");
        request.pngPath = folder.path() / (name + ".png");
        renderer.render(request);
        ++renders;
        // A replicated presentation is cropped and magnified here: the prediction is on what an observer sees.
        applyPresentation(request.exrPath, request.pngPath, stimulus.presentation);
        cv::Mat image =
            metrics::loadMetricRender(request.pngPath, metrics::RenderRole::test, metrics::ImageEncoding::srgb).beauty;
        fs::remove(request.exrPath);
        fs::remove(request.pngPath);
        return image;
    };
    const cv::Mat reference = render(*referenceStimulus, referenceOverrides);
    auto predictedJod = [&](double v) {
        const cv::Mat test = render(*base, varied.overridesAt(v));
        if (test.size() != reference.size())
            throwInput(specName, "",
                       "stimulus '" + base->id + "' and its reference '" + report.reference + "' differ in size");
        const double jod = metrics::cvvdp(reference, test, display, false).jod;
        spdlog::info("calibrate: {}={}: {:.3f} JOD (difference {:.3f})", key, levelText(v, report.integral), jod,
                     10.0 - jod);
        return jod;
    };
    report.result = searchLevels(predictedJod, options.targets, report.search);
    report.renders = renders;
    report.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return report;
}

std::string levelsToml(const CalibrationReport& report) {
    std::vector<const CalibratedLevel*> reached;
    for (const auto& level : report.result.levels)
        if (level.reached &&
            std::none_of(reached.begin(), reached.end(), [&](const auto* r) { return r->value == level.value; }))
            reached.push_back(&level);
    std::sort(reached.begin(), reached.end(), [](const auto* a, const auto* b) { return a->value < b->value; });
    std::string out = "# Levels of " + report.key +
                      " calibrated by `skinlab stimuli calibrate` (ColorVideoVDP): stimulus '" + report.stimulus +
                      "' of set '" + report.set + "' against '" + report.reference + "'\n";
    out += "# display " + report.display + "\n";
    out += "# target JOD, achieved JOD (tolerance " + number(report.search.tolerance, "%g") + "):";
    for (const auto& level : report.result.levels)
        out += std::string(&level == &report.result.levels.front() ? " " : ", ") + number(level.targetJod, "%g") +
               " → " + (level.reached ? number(level.achievedJod) : std::string("not reached"));
    out += "\n[[factor]]\nname = \"" + report.factor + "\"\nlevels = [";
    for (size_t i = 0; i < reached.size(); ++i) out += (i ? ", " : "") + levelText(reached[i]->value, report.integral);
    out += "]\n";
    return out;
}

} // namespace skinlab::stimuli
