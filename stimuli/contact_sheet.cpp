#include "stimuli/contact_sheet.h"

#include "common/error.h"
#include "common/html.h"
#include "common/files.h"
#include "stimuli/naming.h"
#include "stimuli/visibility.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <algorithm>
#include <cstdlib>
#include <cmath>
#include <map>
#include <optional>
#include <sstream>

namespace skinlab::stimuli {

namespace fs = std::filesystem;

namespace {

struct Block {
    std::string name;
    std::vector<const formats::ManifestEntry*> stimuli;
};

std::vector<Block> groupByBlock(const Manifest& manifest) {
    std::vector<Block> blocks;
    for (const formats::ManifestEntry& s : manifest.stimuli) {
        const std::string& name = s.block;
        auto it = std::find_if(blocks.begin(), blocks.end(), [&](const Block& b) { return b.name == name; });
        if (it == blocks.end()) {
            blocks.push_back({name, {}});
            it = blocks.end() - 1;
        }
        it->stimuli.push_back(&s);
    }
    return blocks;
}

std::string valueText(const nlohmann::json& value) {
    return value.is_string() ? value.get<std::string>() : value.dump();
}

// The factor levels that tell the stimuli of one block apart (the caption of a thumbnail), in the spec's factor order
// (the entries' own order is alphabetical).
std::vector<std::string> varyingFactors(const Manifest& manifest, const Block& block) {
    std::vector<std::string> names;
    for (const auto& f : manifest.factors) names.push_back(f.value("name", ""));
    for (const auto* s : block.stimuli)
        for (auto it = s->factors.begin(); it != s->factors.end(); ++it)
            if (std::find(names.begin(), names.end(), it.key()) == names.end()) names.push_back(it.key());
    std::vector<std::string> varying;
    for (const auto& name : names) {
        std::string first;
        bool differs = false;
        for (size_t i = 0; i < block.stimuli.size(); ++i) {
            const std::string v = block.stimuli[i]->factorText(name);
            if (i == 0) first = v;
            else if (v != first) differs = true;
        }
        if (differs) varying.push_back(name);
    }
    return varying;
}

// A level as a caption word: its label when the spec gave the factor words or paths ("bleed" for a scene file,
// "separable"); numbers and booleans with their factor's name, which they do not name themselves ("cbf=true",
// "lab_weight=0.09", "transmittance.enabled=true"); a scene that is no level of the factor (a block's reference
// may render its own) by its short name ("bleed-true-mask"). (Manifest factor values are the levels as text.)
std::string levelText(const Manifest& manifest, const std::string& factor, const nlohmann::json& value) {
    const std::string text = valueText(value);
    bool bare = text == "true" || text == "false" || value.is_number();
    if (!bare && !text.empty()) {
        char* end = nullptr;
        std::strtod(text.c_str(), &end);
        bare = end && *end == '\0';
    }
    if (bare) {
        const std::string name = factor.rfind("sss.", 0) == 0 ? factor.substr(4) : factor;
        return name + "=" + text;
    }
    for (const auto& f : manifest.factors) {
        if (f.value("name", "") != factor || !f.contains("levels")) continue;
        for (const auto& level : f["levels"])
            if (level.value("value", "") == text && !level.value("label", "").empty())
                return level["label"].get<std::string>();
    }
    if (factor == "scene") {
        const std::string label = sceneLabel(text);
        if (!label.empty()) return label;
    }
    return text;
}

std::string caption(const Manifest& manifest, const formats::ManifestEntry& stimulus,
                    const std::vector<std::string>& varying) {
    std::string text;
    const nlohmann::json& f = stimulus.factors;
    for (const auto& name : varying)
        if (f.contains(name)) text += (text.empty() ? "" : " ") + levelText(manifest, name, f.at(name));
    const bool reference = stimulus.reference;
    if (reference) text += text.empty() ? "reference" : " (ref)";
    if (text.empty()) text = stimulus.id;
    // The visibility ColorVideoVDP predicts against the block's reference, when the build recorded it (not on the
    // reference itself: 10 JOD by definition).
    if (!reference && stimulus.predicted) {
        char jod[64];
        std::snprintf(jod, sizeof jod, " - predicted %.2f JOD", stimulus.predicted->jod);
        text += jod;
    }
    return text;
}

// Splits a caption into lines no wider than `width` pixels at 13 px (OpenImageIO's text_size with `font`), at
// spaces; a word wider than a line is cut. At most `maxLines` lines; "..." marks text left out (ASCII: the PNG font has no other glyphs).
std::vector<std::string> wrapCaption(const std::string& caption, int width, int maxLines, const std::string& font) {
    auto fits = [&](const std::string& text) {
        const OIIO::ROI box = OIIO::ImageBufAlgo::text_size(text, 13, font);
        return !box.defined() || box.width() <= width; // no font: nothing is drawn anyway
    };
    std::vector<std::string> words;
    std::istringstream in(caption);
    for (std::string word; in >> word;) words.push_back(word);
    std::vector<std::string> lines;
    std::string current;
    for (std::string word : words) {
        while (!fits(word) && word.size() > 1) word.pop_back();
        const std::string joined = current.empty() ? word : current + " " + word;
        if (fits(joined)) {
            current = joined;
            continue;
        }
        lines.push_back(current);
        current = word;
    }
    if (!current.empty()) lines.push_back(current);
    if (static_cast<int>(lines.size()) > maxLines) {
        lines.resize(static_cast<size_t>(maxLines));
        std::string& last = lines.back();
        while (!last.empty() && !fits(last + "...")) last.pop_back();
        last += "...";
    }
    return lines;
}

// How a block is presented, from its first stimulus' manifest entry: "crop 120,40 320×180 of 896×504, ×3 →
// 960×540 px (rendered natively)" (empty for a whole frame at magnification 1, or an entry without a presentation).
std::string presentationText(const Block& block, bool ascii = false) {
    const std::string times = ascii ? "x" : "×", arrow = ascii ? "->" : "→";
    if (block.stimuli.empty() || !block.stimuli.front()->presentation) return "";
    const nlohmann::json& p = *block.stimuli.front()->presentation;
    const nlohmann::json& c = p.at("crop");
    const nlohmann::json& r = p.at("render");
    const int m = p.at("magnification").get<int>();
    const bool whole = c.at("x").get<int>() == 0 && c.at("y").get<int>() == 0 && c.at("width") == r.at("width") &&
                       c.at("height") == r.at("height");
    if (whole && m == 1) return "";
    std::string text = whole ? "whole " + valueText(r.at("width")) + times + valueText(r.at("height")) + " frame"
                             : "crop " + valueText(c.at("x")) + "," + valueText(c.at("y")) + " " +
                                   valueText(c.at("width")) + times + valueText(c.at("height")) + " of " +
                                   valueText(r.at("width")) + times + valueText(r.at("height"));
    text += ", " + times + std::to_string(m) + " " + arrow + " " + valueText(p.at("presented").at("width")) + times +
            valueText(p.at("presented").at("height")) + " px";
    if (m > 1 && p.contains("method"))
        text += p.at("method") == "native" ? " (rendered natively)" : " (nearest-neighbour replication)";
    return text;
}

// The block's rows of visibility.json as a table: JOD at each ppd, and where the comparison stops being visible.
std::string visibilityTableHtml(const nlohmann::json& visibility, const std::string& block) {
    std::ostringstream out;
    const nlohmann::json& ppd = visibility.at("pixels_per_degree");
    const nlohmann::json& distance = visibility.at("distance_m");
    bool any = false;
    for (const nlohmann::json& row : visibility.at("rows")) any = any || row.at("block") == block;
    if (!any) return "";
    const auto cell = [](double value, const char* format) {
        char text[32];
        std::snprintf(text, sizeof text, format, value);
        return std::string(text);
    };
    out << "<table class=\"visibility\"><thead><tr><th>condition</th>";
    for (size_t k = 0; k < ppd.size(); ++k) {
        out << "<th>" << cell(ppd[k].get<double>(), "%g") << " ppd";
        if (distance.is_array()) out << "<br>" << cell(distance[k].get<double>(), "%.2f") << " m";
        out << "</th>";
    }
    out << "<th>visible (below " << cell(visibility.value("visible_below_jod", 9.0), "%g")
        << " JOD) up to</th></tr></thead><tbody>";
    for (const nlohmann::json& row : visibility.at("rows")) {
        if (row.at("block") != block) continue;
        out << "<tr><td class=\"id\">" << escapeHtml(row.at("stimulus").get<std::string>()) << "</td>";
        for (const nlohmann::json& jod : row.at("jod")) {
            const double v = jod.get<double>();
            out << "<td" << (v < visibility.value("visible_below_jod", 9.0) ? " class=\"visible\"" : "") << ">"
                << cell(v, "%.2f") << "</td>";
        }
        std::string limit;
        if (row.value("visible_everywhere", false)) limit = "beyond " + cell(ppd.back().get<double>(), "%g") + " ppd";
        else if (row.value("invisible_everywhere", false))
            limit = "not visible at " + cell(ppd.front().get<double>(), "%g") + " ppd";
        else if (row.at("one_jod_limit").is_object()) {
            const nlohmann::json& l = row["one_jod_limit"];
            limit = cell(l.at("pixels_per_degree").get<double>(), "%.0f") + " ppd";
            if (l.contains("distance_m")) limit += " (" + cell(l["distance_m"].get<double>(), "%.2f") + " m)";
        }
        out << "<td>" << escapeHtml(limit) << "</td></tr>";
    }
    out << "</tbody></table>\n";
    return out.str();
}

std::string html(const Manifest& manifest, const std::vector<Block>& blocks,
                 const std::optional<nlohmann::json>& visibility) {
    std::ostringstream out;
    out << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>" << escapeHtml(manifest.set)
        << " — skinlab stimulus set</title>\n<style>\n"
        << "body{font-family:sans-serif;background:#222;color:#ddd;margin:1em}\n"
        << "h2{border-bottom:1px solid #555;padding-bottom:.2em}\n"
        << ".grid{display:flex;flex-wrap:wrap;gap:12px}\n"
        << "figure{margin:0;background:#2c2c2c;padding:6px;border:2px solid transparent}\n"
        << "figure.reference{border-color:#c90}\n"
        << "img{display:block;max-width:320px;height:auto}\n"
        << ".presentation{color:#aaa;font-size:13px}\n"
        << "figcaption{font-size:12px;margin-top:4px}\n.id{font-family:monospace;color:#aaa}\n"
        << "table{border-collapse:collapse}td{padding:0 .6em 0 0;vertical-align:top}\n"
        << "table.visibility{margin:.5em 0 1em}table.visibility th,table.visibility td{padding:2px 8px;"
           "text-align:right;border-bottom:1px solid #444;font-size:13px}table.visibility "
           "td.id{text-align:left}table.visibility td.visible{color:#fc6}\n"
        << ".plot{background:#fff;max-width:100%}\n"
        << "</style>\n</head>\n<body>\n<h1>Stimulus set " << escapeHtml(manifest.set) << "</h1>\n";
    if (!manifest.description.empty()) out << "<p>" << escapeHtml(manifest.description) << "</p>\n";
    out << "<p>" << manifest.stimuli.size() << " stimuli in " << blocks.size()
        << " block(s). Renderer: " << escapeHtml(manifest.renderer.glRenderer) << " (skinlab "
        << escapeHtml(manifest.renderer.skinlabVersion) << "). Fixed: ";
    std::string fixed;
    for (auto it = manifest.fixed.begin(); it != manifest.fixed.end(); ++it)
        fixed += (fixed.empty() ? "" : ", ") + it.key() + " = " + valueText(it.value());
    out << escapeHtml(fixed.empty() ? "(scene defaults)" : fixed) << ".</p>\n";
    if (visibility) {
        const nlohmann::json& d = visibility->at("display");
        out << "<h2>Visibility against viewing distance</h2>\n<p>ColorVideoVDP of every condition against its block's "
               "reference on the presented images, at each pixels per degree (display "
            << escapeHtml(d.value("name", std::string())) << "'s photometry"
            << (visibility->at("distance_m").is_array() ? "; distances on its screen size" : "") << "). Below "
            << visibility->value("visible_below_jod", 9.0)
            << " JOD (highlighted) 75 % of observers tell the condition from the reference. Tables per block below; "
               "<code>visibility.csv</code>, <code>visibility.json</code>.</p>\n"
            << "<img class=\"plot\" src=\"visibility.svg\" alt=\"JOD against pixels per degree, per block\">\n";
    }
    for (const auto& block : blocks) {
        const std::string presented = presentationText(block);
        out << "<h2>" << escapeHtml(block.name.empty() ? "(all)" : block.name) << "</h2>\n";
        if (!presented.empty()) out << "<p class=\"presentation\">Presented: " << escapeHtml(presented) << "</p>\n";
        if (visibility) out << visibilityTableHtml(*visibility, block.name);
        out << "<div class=\"grid\">\n";
        for (const auto* s : block.stimuli) {
            const bool reference = s->reference;
            const std::string& png = s->files.png;
            out << "<figure" << (reference ? " class=\"reference\"" : "") << "><a href=\"" << escapeHtml(png)
                << "\"><img src=\"" << escapeHtml(png) << "\" alt=\"" << escapeHtml(s->id)
                << "\" loading=\"lazy\"></a>\n<figcaption><div class=\"id\">" << escapeHtml(s->id)
                << (reference ? " — reference" : "") << "</div><table>";
            const nlohmann::json& f = s->factors;
            for (auto it = f.begin(); it != f.end(); ++it)
                out << "<tr><td>" << escapeHtml(it.key()) << "</td><td>" << escapeHtml(valueText(it.value()))
                    << "</td></tr>";
            out << "</table></figcaption></figure>\n";
        }
        out << "</div>\n";
    }
    out << "</body>\n</html>\n";
    return out.str();
}

OIIO::ImageBuf thumbnail(const fs::path& png, int width, int height) {
    OIIO::ImageBuf source(png.string());
    if (!source.read(0, 0, true, OIIO::TypeDesc::FLOAT))
        throw RuntimeError(png.string() + ": cannot read for the contact sheet (" + source.geterror() + ")");
    if (source.nchannels() != 3) {
        int order[3] = {0, std::min(1, source.nchannels() - 1), std::min(2, source.nchannels() - 1)};
        source = OIIO::ImageBufAlgo::channels(source, 3, order);
    }
    return OIIO::ImageBufAlgo::resize(source, "", 0.0f, OIIO::ROI(0, width, 0, height, 0, 1, 0, 3));
}

void writePng(const fs::path& path, const Manifest& manifest, const std::vector<Block>& blocks, int thumbWidth,
              const fs::path& dir) {
    if (manifest.stimuli.empty()) return;
    // Each block's thumbnails keep its stimuli's aspect (blocks may be cropped differently).
    auto thumbHeightOf = [&](const Block& b) {
        const auto& first = *b.stimuli.front();
        const int imageWidth = std::max(1, first.width);
        const int imageHeight = std::max(1, first.height);
        return std::max(1, static_cast<int>(std::lround(double(thumbWidth) * imageHeight / imageWidth)));
    };
    // Captions wrap at word boundaries to the thumbnail's width, up to kCaptionLines lines (the last one cut).
    constexpr int margin = 8, titleHeight = 22, lineHeight = 16, kCaptionLines = 3, maxColumns = 8;
    constexpr int captionHeight = lineHeight * kCaptionLines + 2;
    size_t columns = 1;
    for (const auto& b : blocks) columns = std::max(columns, std::min<size_t>(b.stimuli.size(), maxColumns));
    int height = margin;
    for (const auto& b : blocks) {
        size_t rows = (b.stimuli.size() + maxColumns - 1) / maxColumns;
        height += titleHeight + static_cast<int>(rows) * (thumbHeightOf(b) + captionHeight + margin);
    }
    const int width = margin + static_cast<int>(columns) * (thumbWidth + margin);
    OIIO::ImageBuf sheet(OIIO::ImageSpec(width, height, 3, OIIO::TypeDesc::FLOAT));
    const float background[3] = {0.13f, 0.13f, 0.13f}, text[3] = {0.9f, 0.9f, 0.9f}, accent[3] = {0.8f, 0.55f, 0.0f};
    OIIO::ImageBufAlgo::fill(sheet, background);
    // Captions need a TrueType font through FreeType; without one the grid is still written (the HTML page
    // carries the labels), so a failed render_text is not an error.
    // OpenImageIO's default font (DroidSans) is not packaged by Debian; DejaVu (fonts-dejavu-core) usually is.
    std::string font;
    for (const char* candidate : {"/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
                                  "/usr/share/fonts/TTF/DejaVuSans.ttf", "/usr/share/fonts/dejavu/DejaVuSans.ttf"})
        if (fs::exists(candidate)) {
            font = candidate;
            break;
        }
    auto label = [&](int x, int y, const std::string& s, const float* colour) {
        if (!OIIO::ImageBufAlgo::render_text(sheet, x, y, s, 13, font, OIIO::cspan<float>(colour, 3)))
            (void)sheet.geterror();
    };
    int y = margin;
    for (const auto& b : blocks) {
        // The thumbnails' captions are drawn in ASCII (the font may lack × and →).
        const std::string presented = presentationText(b, true);
        label(margin, y + 15, (b.name.empty() ? manifest.set : b.name) + (presented.empty() ? "" : "  -  " + presented),
              text);
        y += titleHeight;
        const int thumbHeight = thumbHeightOf(b);
        std::vector<std::string> varying = varyingFactors(manifest, b);
        for (size_t i = 0; i < b.stimuli.size(); ++i) {
            const auto& s = *b.stimuli[i];
            int column = static_cast<int>(i % maxColumns);
            if (i > 0 && column == 0) y += thumbHeight + captionHeight + margin;
            int x = margin + column * (thumbWidth + margin);
            OIIO::ImageBuf thumb = thumbnail(dir / s.files.png, thumbWidth, thumbHeight);
            OIIO::ImageBufAlgo::paste(sheet, x, y, 0, 0, thumb);
            const bool reference = s.reference;
            const std::vector<std::string> lines =
                wrapCaption(caption(manifest, s, varying), thumbWidth, kCaptionLines, font);
            for (size_t line = 0; line < lines.size(); ++line)
                label(x, y + thumbHeight + 14 + static_cast<int>(line) * lineHeight, lines[line],
                      reference ? accent : text);
        }
        y += thumbHeight + captionHeight + margin;
    }
    AtomicOutput out(path);
    if (!sheet.write(out.tempPath().string(), OIIO::TypeDesc::UINT8))
        throw RuntimeError(path.string() + ": cannot write (" + sheet.geterror() + ")");
    out.commit();
}

} // namespace

std::vector<std::string> contactSheetCaptions(const Manifest& manifest) {
    std::vector<std::string> captions;
    for (const Block& block : groupByBlock(manifest)) {
        const std::vector<std::string> varying = varyingFactors(manifest, block);
        for (const auto* s : block.stimuli) captions.push_back(caption(manifest, *s, varying));
    }
    return captions;
}

ContactSheetFiles writeContactSheet(const fs::path& dir, const Manifest& manifest, int thumbnailWidth) {
    std::vector<Block> blocks = groupByBlock(manifest);
    ContactSheetFiles files{dir / "contact.html", dir / "contact.png"};
    writeFileAtomic(files.html, html(manifest, blocks, currentVisibility(dir, manifest)));
    if (manifest.stimuli.empty()) {
        files.png.clear();
        return files;
    }
    writePng(files.png, manifest, blocks, thumbnailWidth, dir);
    return files;
}

} // namespace skinlab::stimuli
