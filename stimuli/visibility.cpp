#include "stimuli/visibility.h"

#include "analysis/metrics/metric_render.h"
#include "common/csv.h"
#include "common/error.h"
#include "common/files.h"
#include "common/html.h"
#include "common/version.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>

namespace skinlab::stimuli {
namespace fs = std::filesystem;

namespace {

constexpr double kPi = 3.14159265358979323846;

std::string number(double value, const char* format = "%.4g") {
    char text[48];
    std::snprintf(text, sizeof text, format, value);
    return text;
}

// The row's 9-JOD crossing, linear in log ppd.
void findLimit(VisibilityRow& row, const std::vector<double>& ppd) {
    const auto visible = [](double jod) { return jod < kVisibleBelowJod; };
    row.visibleEverywhere = std::all_of(row.jod.begin(), row.jod.end(), visible);
    row.invisibleEverywhere = std::none_of(row.jod.begin(), row.jod.end(), visible);
    // The largest ppd (farthest distance) up to which the comparison stays visible: the last visible→invisible step.
    for (size_t i = ppd.size() - 1; i > 0; --i) {
        const double a = row.jod[i - 1], b = row.jod[i];
        if (visible(a) && !visible(b)) {
            const double t = (kVisibleBelowJod - a) / (b - a);
            row.limitPixelsPerDegree = std::exp(std::log(ppd[i - 1]) + t * (std::log(ppd[i]) - std::log(ppd[i - 1])));
            return;
        }
    }
}

} // namespace

std::optional<double> viewingDistanceAt(const metrics::CvvdpDisplay& display, double pixelsPerDegree) {
    if (display.resolutionWidth <= 0 || display.resolutionHeight <= 0 || display.diagonalInches <= 0.0)
        return std::nullopt;
    const double w = display.resolutionWidth, h = display.resolutionHeight;
    const double widthMetres = display.diagonalInches * 0.0254 * w / std::sqrt(w * w + h * h);
    const double pitch = widthMetres / w;
    // ppd = 1 / (2·atan(pitch / (2·d)) in degrees), solved for d.
    return pitch / (2.0 * std::tan(kPi / 360.0 / pixelsPerDegree));
}

VisibilityTable computeVisibility(const fs::path& dir, const Manifest& manifest, const VisibilityOptions& options) {
    const auto started = std::chrono::steady_clock::now();
    if (options.pixelsPerDegree.empty()) throwInput("--ppd", "", "at least one value is needed");
    for (size_t i = 0; i < options.pixelsPerDegree.size(); ++i) {
        const double p = options.pixelsPerDegree[i];
        if (!(p > 0.0) || !std::isfinite(p)) throwInput("--ppd", "", number(p, "%g") + " must be a positive number");
        if (i > 0 && !(p > options.pixelsPerDegree[i - 1]))
            throwInput("--ppd", "", number(p, "%g") + " is not larger than the value before it (give them ascending)");
    }
    if (options.jobs < 1) throwInput("--jobs", "", std::to_string(options.jobs) + " is not a positive number");
    if (!manifest.complete)
        throwInput((dir / "manifest.json").string(), "", "the set is not complete (build it first)");

    VisibilityTable table;
    table.displaySource = "--display";
    if (!options.display.empty()) {
        table.display = metrics::cvvdpDisplay(options.display);
    } else {
        // The display of the set's predictions, named or custom (recorded in full), else the default.
        const formats::Prediction* recorded = nullptr;
        for (const formats::ManifestEntry& s : manifest.stimuli)
            if (s.predicted && !s.predicted->display.empty()) recorded = &*s.predicted;
        table.displaySource = recorded ? "the set's predictions" : "default";
        table.display = !recorded                ? metrics::cvvdpDisplay("standard_fhd")
                        : recorded->displayModel ? metrics::cvvdpDisplayOf(*recorded->displayModel)
                                                 : metrics::cvvdpDisplay(recorded->display);
    }
    table.pixelsPerDegree = options.pixelsPerDegree;
    for (double p : table.pixelsPerDegree)
        if (const auto d = viewingDistanceAt(table.display, p)) table.distanceMetres.push_back(*d);
    if (table.distanceMetres.size() != table.pixelsPerDegree.size()) table.distanceMetres.clear();

    // Rows: every non-reference stimulus of a block with a reference, in manifest order.
    std::map<std::string, const formats::ManifestEntry*> referenceOf;
    for (const formats::ManifestEntry& s : manifest.stimuli)
        if (s.reference) referenceOf.emplace(s.block, &s);
    if (referenceOf.empty())
        throwInput((dir / "manifest.json").string(), "", "no block has a reference stimulus: nothing to compare with");
    std::vector<std::pair<const formats::ManifestEntry*, const formats::ManifestEntry*>> pairs; // test, reference
    for (const formats::ManifestEntry& s : manifest.stimuli) {
        const auto found = referenceOf.find(s.block);
        if (found == referenceOf.end() || &s == found->second) continue;
        pairs.emplace_back(&s, found->second);
        table.rows.push_back({s.block, found->second->id, s.id, std::vector<double>(table.pixelsPerDegree.size(), 10.0),
                              std::nullopt, false, false});
        table.pngSha256[s.id] = s.sha256.png;
        table.pngSha256[found->second->id] = found->second->sha256.png;
    }

    // Rows block by block (blocks in order of their first stimulus), stimuli in manifest order inside a block.
    {
        std::vector<std::string> order;
        for (const VisibilityRow& row : table.rows)
            if (std::find(order.begin(), order.end(), row.block) == order.end()) order.push_back(row.block);
        const auto rank = [&](const std::string& block) { return std::find(order.begin(), order.end(), block); };
        std::vector<size_t> index(table.rows.size());
        for (size_t i = 0; i < index.size(); ++i) index[i] = i;
        std::stable_sort(index.begin(), index.end(),
                         [&](size_t a, size_t b) { return rank(table.rows[a].block) < rank(table.rows[b].block); });
        std::vector<VisibilityRow> rows;
        std::vector<std::pair<const formats::ManifestEntry*, const formats::ManifestEntry*>> sortedPairs;
        for (size_t i : index) {
            rows.push_back(table.rows[i]);
            sortedPairs.push_back(pairs[i]);
        }
        table.rows = std::move(rows);
        pairs = std::move(sortedPairs);
    }
    // Each image decoded once; every (row, ppd) a task.
    std::map<std::string, cv::Mat> images; // stimulus id → linear display RGB
    for (const auto& [test, reference] : pairs)
        for (const formats::ManifestEntry* s : {test, reference}) {
            if (!images.count(s->id))
                images[s->id] = metrics::loadMetricRender(dir / s->files.png, metrics::RenderRole::test,
                                                          metrics::ImageEncoding::srgb)
                                    .beauty;
        }
    std::vector<metrics::CvvdpDisplay> displays;
    for (double p : table.pixelsPerDegree) {
        metrics::CvvdpDisplayOverrides overrides;
        overrides.pixelsPerDegree = p;
        displays.push_back(metrics::applyCvvdpOverrides(table.display, overrides));
    }
    const size_t tasks = table.rows.size() * displays.size();
    std::atomic<size_t> next{0};
    std::mutex failure;
    std::string error;
    const auto work = [&] {
        for (size_t t = next++; t < tasks; t = next++) {
            VisibilityRow& row = table.rows[t / displays.size()];
            const size_t k = t % displays.size();
            try {
                row.jod[k] = metrics::cvvdp(images.at(row.reference), images.at(row.stimulus), displays[k], false).jod;
            } catch (const std::exception& e) {
                std::lock_guard lock(failure);
                error = row.stimulus + ": " + e.what();
            }
        }
    };
    std::vector<std::thread> threads;
    for (int j = 1; j < std::min<int>(options.jobs, static_cast<int>(tasks)); ++j) threads.emplace_back(work);
    work();
    for (std::thread& t : threads) t.join();
    if (!error.empty()) throw RuntimeError("visibility: " + error);
    for (VisibilityRow& row : table.rows) findLimit(row, table.pixelsPerDegree);
    table.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    return table;
}

nlohmann::json visibilityJson(const VisibilityTable& table) {
    nlohmann::json rows = nlohmann::json::array();
    for (const VisibilityRow& row : table.rows) {
        nlohmann::json limit;
        if (row.limitPixelsPerDegree) {
            limit = {{"pixels_per_degree", *row.limitPixelsPerDegree}};
            if (const auto d = viewingDistanceAt(table.display, *row.limitPixelsPerDegree)) limit["distance_m"] = *d;
        }
        rows.push_back({{"block", row.block},
                        {"reference", row.reference},
                        {"stimulus", row.stimulus},
                        {"jod", row.jod},
                        {"one_jod_limit", limit},
                        {"visible_everywhere", row.visibleEverywhere},
                        {"invisible_everywhere", row.invisibleEverywhere}});
    }
    return {{"format", "skinlab-visibility"},
            {"version", 1},
            {"skinlab_version", version()},
            {"metric", "ColorVideoVDP v0.5.6, on the presented PNGs"},
            {"display",
             {{"name", table.display.name},
              {"description", table.display.description},
              {"source", table.displaySource},
              {"pixels_per_degree", table.display.pixelsPerDegree}}},
            {"pixels_per_degree", table.pixelsPerDegree},
            {"distance_m", table.distanceMetres.empty() ? nlohmann::json() : nlohmann::json(table.distanceMetres)},
            {"visible_below_jod", kVisibleBelowJod},
            {"png_sha256", table.pngSha256},
            {"seconds", table.seconds},
            {"rows", rows}};
}

std::string visibilityCsv(const VisibilityTable& table) {
    std::string out = "block,reference,stimulus";
    for (double p : table.pixelsPerDegree) out += ",jod_ppd_" + number(p, "%g");
    out += ",one_jod_ppd,one_jod_distance_m,visible_everywhere,invisible_everywhere\n";
    for (const VisibilityRow& row : table.rows) {
        out += csvField(row.block) + "," + csvField(row.reference) + "," + csvField(row.stimulus);
        for (double jod : row.jod) out += "," + number(jod, "%.4f");
        std::string ppd, distance;
        if (row.limitPixelsPerDegree) {
            ppd = number(*row.limitPixelsPerDegree, "%.2f");
            if (const auto d = viewingDistanceAt(table.display, *row.limitPixelsPerDegree))
                distance = number(*d, "%.3f");
        }
        out += "," + ppd + "," + distance + "," + (row.visibleEverywhere ? "1" : "0") + "," +
               (row.invisibleEverywhere ? "1" : "0") + "\n";
    }
    return out;
}

std::string visibilitySvg(const VisibilityTable& table) {
    // One panel per block: JOD (down = more visible) against ppd on a log axis, a line per condition.
    std::vector<std::string> blocks;
    for (const VisibilityRow& row : table.rows)
        if (std::find(blocks.begin(), blocks.end(), row.block) == blocks.end()) blocks.push_back(row.block);
    const double panelWidth = 960, plotLeft = 60, plotWidth = 420, plotTop = 58, plotHeight = 220, panelHeight = 336;
    const double lo = std::log(table.pixelsPerDegree.front()), hi = std::log(table.pixelsPerDegree.back());
    const auto xOf = [&](double ppd) {
        return plotLeft + (hi > lo ? (std::log(ppd) - lo) / (hi - lo) : 0.5) * plotWidth;
    };
    static const char* colours[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd",
                                    "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"};
    std::ostringstream svg;
    svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << panelWidth << "\" height=\""
        << panelHeight * static_cast<double>(blocks.size()) << "\" font-family=\"sans-serif\" font-size=\"11\">\n"
        << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
    for (size_t b = 0; b < blocks.size(); ++b) {
        const double top = panelHeight * static_cast<double>(b);
        double floor = 9.0;
        for (const VisibilityRow& row : table.rows)
            if (row.block == blocks[b])
                for (double jod : row.jod) floor = std::min(floor, std::floor(jod));
        const auto yOf = [&](double jod) { return top + plotTop + (10.0 - jod) / (10.0 - floor) * plotHeight; };
        svg << "<g>\n<text x=\"" << plotLeft << "\" y=\"" << top + 16 << "\" font-size=\"13\" font-weight=\"bold\">"
            << escapeHtml(blocks[b]) << "</text>\n";
        svg << "<rect x=\"" << plotLeft << "\" y=\"" << top + plotTop << "\" width=\"" << plotWidth << "\" height=\""
            << plotHeight << "\" fill=\"none\" stroke=\"#444\"/>\n";
        // Grid and ticks: JOD every 1 (every 2 beyond 6 steps), ppd at each computed value.
        const double step = 10.0 - floor > 6.0 ? 2.0 : (10.0 - floor > 3.0 ? 1.0 : 0.5);
        for (double jod = 10.0; jod >= floor - 1e-9; jod -= step)
            svg << "<line x1=\"" << plotLeft << "\" x2=\"" << plotLeft + plotWidth << "\" y1=\"" << yOf(jod)
                << "\" y2=\"" << yOf(jod) << "\" stroke=\"#ddd\"/><text x=\"" << plotLeft - 6 << "\" y=\""
                << yOf(jod) + 4 << "\" text-anchor=\"end\">" << number(jod, "%g") << "</text>\n";
        for (size_t k = 0; k < table.pixelsPerDegree.size(); ++k) {
            const double x = xOf(table.pixelsPerDegree[k]);
            svg << "<line x1=\"" << x << "\" x2=\"" << x << "\" y1=\"" << top + plotTop << "\" y2=\""
                << top + plotTop + plotHeight << "\" stroke=\"#eee\"/><text x=\"" << x << "\" y=\""
                << top + plotTop + plotHeight + 14 << "\" text-anchor=\"middle\">"
                << number(table.pixelsPerDegree[k], "%g") << "</text>\n";
            if (!table.distanceMetres.empty())
                svg << "<text x=\"" << x << "\" y=\"" << top + plotTop - 6 << "\" text-anchor=\"middle\" fill=\"#666\">"
                    << number(table.distanceMetres[k], "%.2f") << "</text>\n";
        }
        svg << "<text x=\"" << plotLeft + plotWidth / 2 << "\" y=\"" << top + plotTop + plotHeight + 30
            << "\" text-anchor=\"middle\">pixels per degree (log scale)</text>\n";
        if (!table.distanceMetres.empty())
            svg << "<text x=\"" << plotLeft + plotWidth / 2 << "\" y=\"" << top + 34
                << "\" text-anchor=\"middle\" fill=\"#666\">viewing distance in m on " << escapeHtml(table.display.name)
                << "</text>\n";
        svg << "<text transform=\"translate(" << 16 << "," << top + plotTop + plotHeight / 2
            << ") rotate(-90)\" text-anchor=\"middle\">JOD against the reference</text>\n";
        // The 1-JOD line: below it, 75 % of observers tell the condition from the reference.
        svg << "<line x1=\"" << plotLeft << "\" x2=\"" << plotLeft + plotWidth << "\" y1=\"" << yOf(kVisibleBelowJod)
            << "\" y2=\"" << yOf(kVisibleBelowJod) << "\" stroke=\"#000\" stroke-dasharray=\"5,4\"/>\n";
        int c = 0;
        for (const VisibilityRow& row : table.rows) {
            if (row.block != blocks[b]) continue;
            const char* colour = colours[c % 10];
            const char* dash = c >= 10 ? " stroke-dasharray=\"2,2\"" : "";
            svg << "<polyline fill=\"none\" stroke=\"" << colour << "\" stroke-width=\"1.8\"" << dash << " points=\"";
            for (size_t k = 0; k < row.jod.size(); ++k)
                svg << (k ? " " : "") << number(xOf(table.pixelsPerDegree[k]), "%.1f") << ","
                    << number(yOf(row.jod[k]), "%.1f");
            svg << "\"/>\n";
            const double legendY = top + plotTop + 8 + 14.0 * c;
            svg << "<line x1=\"" << plotLeft + plotWidth + 14 << "\" x2=\"" << plotLeft + plotWidth + 34 << "\" y1=\""
                << legendY << "\" y2=\"" << legendY << "\" stroke=\"" << colour << "\" stroke-width=\"2\"" << dash
                << "/><text x=\"" << plotLeft + plotWidth + 40 << "\" y=\"" << legendY + 4 << "\">"
                << escapeHtml(row.stimulus) << "</text>\n";
            ++c;
        }
        svg << "</g>\n";
    }
    svg << "</svg>\n";
    return svg.str();
}

void writeVisibility(const fs::path& dir, const VisibilityTable& table) {
    writeFileAtomic(dir / "visibility.svg", visibilitySvg(table));
    writeFileAtomic(dir / "visibility.csv", visibilityCsv(table));
    writeFileAtomic(dir / "visibility.json", visibilityJson(table).dump(2) + "\n");
}

std::optional<nlohmann::json> currentVisibility(const fs::path& dir, const Manifest& manifest) {
    std::error_code ec;
    if (!fs::is_regular_file(dir / "visibility.json", ec)) return std::nullopt;
    nlohmann::json json;
    try {
        json = nlohmann::json::parse(readFile(dir / "visibility.json"));
    } catch (const std::exception&) {
        return std::nullopt;
    }
    if (json.value("format", "") != "skinlab-visibility" || !json.contains("png_sha256")) return std::nullopt;
    // Every image compared must be the one the manifest lists now, and every stimulus with a reference covered.
    std::map<std::string, std::string> shaOf;
    for (const formats::ManifestEntry& s : manifest.stimuli) shaOf[s.id] = s.sha256.png;
    for (const auto& [id, sha] : json["png_sha256"].items())
        if (!shaOf.count(id) || shaOf[id] != sha.get<std::string>()) return std::nullopt;
    return json;
}

} // namespace skinlab::stimuli
