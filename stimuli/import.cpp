#include "stimuli/import.h"

#include "common/csv.h"
#include "common/error.h"
#include "common/files.h"
#include "common/hash.h"
#include "common/version.h"
#include "stimuli/contact_sheet.h"
#include "stimuli/manifest.h"
#include "stimuli/naming.h"
#include "stimuli/output_folder.h"
#include "stimuli/prediction.h"

#include <OpenImageIO/imageio.h>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>
#include <optional>
#include <toml++/toml.h>

namespace skinlab::stimuli {

namespace fs = std::filesystem;

float srgbToLinear(float encoded) {
    if (encoded <= 0.04045f) return encoded / 12.92f;
    return std::pow((encoded + 0.055f) / 1.055f, 2.4f);
}

float linearToSrgb(float linear) {
    if (!(linear > 0.0f)) return 0.0f; // also NaN
    if (linear >= 1.0f) return 1.0f;
    if (linear <= 0.0031308f) return 12.92f * linear;
    return 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}

namespace {

// Columns with a meaning of their own; every factor column is declared (CSV: "factor:NAME"; TOML: `factors`).
constexpr const char* kReservedColumns[] = {"file",  "id",   "block", "reference",   "encoding",     "exposure_ev",
                                            "depth", "mask", "f_px",  "mm_per_unit", "sss_radius_mm"};
const char* const kColumnsHint = "the columns are file, id, block, reference, encoding, exposure_ev, depth, mask, "
                                 "f_px, mm_per_unit, sss_radius_mm and factor columns (CSV: factor:NAME; TOML: "
                                 "listed in `factors`)";
// The numeric columns that describe the camera of a depth image (EXR metadata skinlab:NAME).
constexpr const char* kCameraColumns[] = {"f_px", "mm_per_unit", "sss_radius_mm"};

bool isReserved(const std::string& column) {
    return std::any_of(std::begin(kReservedColumns), std::end(kReservedColumns),
                       [&](const char* r) { return column == r; });
}

// One line of the table, before any image is opened.
struct Row {
    int line = 0;                  // the row's line in the table (CSV record, TOML [[stimulus]] header)
    std::map<std::string, int> at; // column → line of its value (TOML keys may sit on later lines)
    std::string file;              // as written
    std::optional<std::string> id; // as written
    std::optional<std::string> block;
    bool reference = false;
    std::optional<std::string> encoding;
    std::optional<double> exposureEv;
    std::optional<std::string> depth;     // image of linear view depth (depth.Z, else the first channel), as written
    std::optional<std::string> mask;      // image of the skin mask 0..1 (mask.Y, else the first channel), as written
    std::map<std::string, double> camera; // f_px, mm_per_unit, sss_radius_mm
    std::map<std::string, std::string> factors; // factor → level text (absent when empty)
};

struct Table {
    std::string where;                // the table as named in errors
    std::string text;                 // its bytes
    std::optional<std::string> name;  // TOML `name`
    std::string description;          // TOML `description`
    std::vector<std::string> factors; // declared factor names, in order
    std::vector<Row> rows;
};

// "TABLE:LINE: COLUMN: message".
[[noreturn]] void failAt(const Table& table, int line, const std::string& column, const std::string& message) {
    throwInput(table.where + ":" + std::to_string(line), column, message);
}
// The line of a row's value (TOML keys may sit below the [[stimulus]] header), else the row's line.
int lineOf(const Row& row, const std::string& column) {
    auto it = row.at.find(column);
    return it == row.at.end() ? row.line : it->second;
}
[[noreturn]] void fail(const Table& table, const Row& row, const std::string& column, const std::string& message) {
    failAt(table, lineOf(row, column), column, message);
}

bool parseBoolText(std::string text, bool& out) {
    std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return std::tolower(c); });
    if (text == "true" || text == "1" || text == "yes") out = true;
    else if (text == "false" || text == "0" || text == "no") out = false;
    else return false;
    return true;
}

bool parseNumberText(const std::string& text, double& out) {
    char* end = nullptr;
    out = std::strtod(text.c_str(), &end);
    return !text.empty() && end == text.c_str() + text.size() && std::isfinite(out);
}

void checkFactorName(const Table& table, int line, const std::string& column, const std::string& name,
                     const std::vector<std::string>& declared) {
    if (name.empty()) failAt(table, line, column, "a factor needs a name");
    if (isReserved(name)) failAt(table, line, column, "'" + name + "' is a reserved column, not a factor name");
    if (std::find(declared.begin(), declared.end(), name) != declared.end())
        failAt(table, line, column, "factor '" + name + "' is declared twice");
}

void readCsvTable(Table& table) {
    const auto records = parseCsv(table.text, table.where);
    if (records.empty()) throwInput(table.where, "", "empty table (a header row, then one row per image)");
    const auto& header = records.front();
    std::vector<std::string> columns; // per field: a reserved column or "factor:NAME"
    for (const std::string& column : header.fields) {
        if (std::find(columns.begin(), columns.end(), column) != columns.end())
            failAt(table, header.line, column, "the column is given twice");
        if (column.rfind("factor:", 0) == 0) {
            const std::string name = column.substr(7);
            checkFactorName(table, header.line, column, name, table.factors);
            table.factors.push_back(name);
        } else if (!isReserved(column)) {
            failAt(table, header.line, column, std::string("unknown column (") + kColumnsHint + ")");
        }
        columns.push_back(column);
    }
    if (std::find(columns.begin(), columns.end(), "file") == columns.end())
        failAt(table, header.line, "file", "the header has no 'file' column");
    for (size_t r = 1; r < records.size(); ++r) {
        const auto& record = records[r];
        Row row;
        row.line = record.line;
        if (record.fields.size() != columns.size())
            failAt(table, record.line, "",
                   "the row has " + std::to_string(record.fields.size()) + " fields, the header " +
                       std::to_string(columns.size()));
        for (size_t c = 0; c < columns.size(); ++c) {
            const std::string& column = columns[c];
            const std::string& value = record.fields[c];
            row.at[column] = record.line;
            if (column.rfind("factor:", 0) == 0) {
                row.at[column.substr(7)] = record.line;
                if (!value.empty()) row.factors[column.substr(7)] = value;
                continue;
            }
            if (column == "file") row.file = value;
            if (value.empty()) continue; // an optional column left blank takes its default
            if (column == "id") row.id = value;
            else if (column == "block") row.block = value;
            else if (column == "encoding") row.encoding = value;
            else if (column == "depth") row.depth = value;
            else if (column == "mask") row.mask = value;
            else if (column == "reference") {
                if (!parseBoolText(value, row.reference))
                    failAt(table, record.line, column, "'" + value + "' is not true or false");
            } else if (column == "exposure_ev") {
                double ev = 0;
                if (!parseNumberText(value, ev)) failAt(table, record.line, column, "'" + value + "' is not a number");
                row.exposureEv = ev;
            } else if (column != "file") { // f_px, mm_per_unit, sss_radius_mm
                double number = 0;
                if (!parseNumberText(value, number))
                    failAt(table, record.line, column, "'" + value + "' is not a number");
                row.camera[column] = number;
            }
        }
        table.rows.push_back(std::move(row));
    }
}

int lineOf(const toml::node& node) { return static_cast<int>(node.source().begin.line); }

// A factor level of a TOML table: strings as written, numbers and booleans as their TOML text.
std::optional<std::string> tomlLevel(const toml::node& node) {
    if (auto* s = node.as_string()) return s->get();
    if (node.is_integer() || node.is_floating_point() || node.is_boolean()) return tomlValueText(node);
    return std::nullopt;
}

void readTomlTable(Table& table) {
    toml::table root;
    try {
        root = toml::parse(table.text, table.where);
    } catch (const toml::parse_error& e) {
        failAt(table, static_cast<int>(e.source().begin.line), "", std::string(e.description()));
    }
    for (const auto& [key, node] : root) {
        const std::string k(key.str());
        if (k != "name" && k != "description" && k != "factors" && k != "stimulus")
            failAt(table, lineOf(node), k, "unknown key (the table has name, description, factors and [[stimulus]])");
    }
    if (const toml::node* n = root.get("name")) {
        if (!n->is_string()) failAt(table, lineOf(*n), "name", "must be a string");
        table.name = n->as_string()->get();
    }
    if (const toml::node* n = root.get("description")) {
        if (!n->is_string()) failAt(table, lineOf(*n), "description", "must be a string");
        table.description = n->as_string()->get();
    }
    if (const toml::node* n = root.get("factors")) {
        const toml::array* list = n->as_array();
        if (!list) failAt(table, lineOf(*n), "factors", "must be a list of factor names");
        for (const auto& item : *list) {
            if (!item.is_string()) failAt(table, lineOf(item), "factors", "must be a list of factor names");
            const std::string name = item.as_string()->get();
            checkFactorName(table, lineOf(item), "factors", name, table.factors);
            table.factors.push_back(name);
        }
    }
    const toml::node* stimuli = root.get("stimulus");
    if (!stimuli) throwInput(table.where, "stimulus", "no [[stimulus]] tables");
    const toml::array* list = stimuli->as_array();
    if (!list || !list->is_array_of_tables())
        failAt(table, lineOf(*stimuli), "stimulus", "must be [[stimulus]] tables");
    for (const auto& item : *list) {
        const toml::table& t = *item.as_table();
        Row row;
        row.line = lineOf(t);
        for (const auto& [key, node] : t) {
            const std::string k(key.str());
            const int line = lineOf(node);
            row.at[k] = line;
            const bool isFactor = std::find(table.factors.begin(), table.factors.end(), k) != table.factors.end();
            auto text = [&]() -> std::string {
                if (!node.is_string()) failAt(table, line, k, "must be a string");
                return node.as_string()->get();
            };
            if (isFactor) {
                auto level = tomlLevel(node);
                if (!level) failAt(table, line, k, "a factor level must be a string, a number or a boolean");
                row.factors[k] = *level;
            } else if (k == "file") row.file = text();
            else if (k == "id") row.id = text();
            else if (k == "block") row.block = text();
            else if (k == "encoding") row.encoding = text();
            else if (k == "depth") row.depth = text();
            else if (k == "mask") row.mask = text();
            else if (k == "reference") {
                if (!node.is_boolean()) failAt(table, line, k, "must be true or false");
                row.reference = node.as_boolean()->get();
            } else if (k == "exposure_ev") {
                if (!node.is_number()) failAt(table, line, k, "'" + tomlValueText(node) + "' is not a number");
                row.exposureEv = node.value<double>().value_or(0.0);
            } else if (std::find(std::begin(kCameraColumns), std::end(kCameraColumns), k) != std::end(kCameraColumns)) {
                if (!node.is_number()) failAt(table, line, k, "'" + tomlValueText(node) + "' is not a number");
                row.camera[k] = node.value<double>().value_or(0.0);
            } else {
                failAt(table, line, k, std::string("unknown column (") + kColumnsHint + ")");
            }
        }
        table.rows.push_back(std::move(row));
    }
}

// An image read as float RGB, as stored (display values for sRGB files, linear values for linear ones).
struct Pixels {
    int width = 0;
    int height = 0;
    bool floatingPoint = false; // stored as half/float (EXR, HDR): linear by default
    std::vector<float> rgb;     // width × height × 3
    std::vector<float> plane;   // width × height: the `planeChannel` channel, else the first (a depth or mask image)
};

// Reads RGB of an image (R, G, B by name when present, else the first three channels, a grey image replicated;
// alpha is ignored and never multiplied in). std::nullopt with `reason` when it cannot be read.
std::optional<Pixels> readPixels(const fs::path& path, std::string& reason, const std::string& planeChannel = "") {
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto input = OIIO::ImageInput::open(path.string(), &config);
    if (!input) {
        reason = OIIO::geterror();
        if (reason.empty()) reason = "unknown format";
        return std::nullopt;
    }
    const OIIO::ImageSpec& spec = input->spec();
    if (spec.width < 1 || spec.height < 1 || spec.nchannels < 1 || spec.depth != 1) {
        reason = "not a 2-D image";
        return std::nullopt;
    }
    Pixels p;
    p.width = spec.width;
    p.height = spec.height;
    p.floatingPoint = spec.format.is_floating_point();
    auto channel = [&](const char* name, int fallback) {
        for (int c = 0; c < spec.nchannels; ++c)
            if (spec.channelnames[static_cast<size_t>(c)] == name) return c;
        return spec.nchannels >= 3 ? fallback : 0;
    };
    const int source[3] = {channel("R", 0), channel("G", 1), channel("B", 2)};
    const size_t count = static_cast<size_t>(spec.width) * static_cast<size_t>(spec.height);
    std::vector<float> all(count * static_cast<size_t>(spec.nchannels));
    if (!input->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data())) {
        reason = input->geterror();
        if (reason.empty()) reason = "cannot read its pixels";
        return std::nullopt;
    }
    input->close();
    p.rgb.resize(count * 3);
    p.plane.resize(count);
    int plane = 0; // a skinlab EXR's own depth.Z / mask.Y, so a built set's render can give its AOVs
    for (int c = 0; c < spec.nchannels; ++c)
        if (!planeChannel.empty() && spec.channelnames[static_cast<size_t>(c)] == planeChannel) plane = c;
    const size_t n = static_cast<size_t>(spec.nchannels);
    for (size_t i = 0; i < count; ++i) {
        for (size_t c = 0; c < 3; ++c) p.rgb[i * 3 + c] = all[i * n + static_cast<size_t>(source[c])];
        p.plane[i] = all[i * n + static_cast<size_t>(plane)];
    }
    return p;
}

// A row after every check: where its image is, what it becomes.
struct Checked {
    const Row* row = nullptr;
    std::string id;
    std::string block;
    fs::path path;
    bool linear = false;
    double exposureEv = 0.0;
    int width = 0;
    int height = 0;
    std::string originalSha256;
    fs::path depth, mask; // empty without AOVs
};

void writeImage(const fs::path& path, int width, int height, OIIO::TypeDesc type, const std::vector<float>& pixels,
                const std::vector<std::string>& channels,
                const std::vector<std::pair<std::string, std::string>>& attributes,
                const std::map<std::string, double>& numbers = {}) {
    auto output = OIIO::ImageOutput::create(path.string());
    if (!output) throw RuntimeError(path.string() + ": cannot create an image writer (" + OIIO::geterror() + ")");
    OIIO::ImageSpec spec(width, height, static_cast<int>(channels.size()), type);
    spec.channelnames = channels;
    for (const auto& [key, value] : numbers) spec.attribute("skinlab:" + key, static_cast<float>(value));
    spec.attribute("DateTime", ""); // OpenImageIO would stamp the current time: the files would differ per import
    if (type == OIIO::TypeDesc::FLOAT) spec.attribute("compression", "zip");
    for (const auto& [key, value] : attributes) spec.attribute(key, value);
    if (!output->open(path.string(), spec) || !output->write_image(OIIO::TypeDesc::FLOAT, pixels.data()) ||
        !output->close())
        throw RuntimeError(path.string() + ": cannot write the image (" + output->geterror() + ")");
}

Table readImportTable(const ImportOptions& options) {
    Table table;
    table.where = options.table.string();
    if (!fs::is_regular_file(options.table)) throwInput(table.where, "", "file not found");
    table.text = readFile(options.table);
    const std::string extension = options.table.extension().string();
    if (extension == ".csv") readCsvTable(table);
    else if (extension == ".toml") readTomlTable(table);
    else throwInput(table.where, "", "a table is a .csv or a .toml file");
    if (table.rows.empty()) throwInput(table.where, "", "the table lists no images");
    return table;
}

// The set's name: --name, the table's `name`, or the table's file stem.
std::string importSetName(const ImportOptions& options, const Table& table) {
    std::string set;
    if (!options.name.empty()) {
        if (!isIdSafe(options.name))
            throwInput("--name", "", "'" + options.name + "' is not a set name (a-z 0-9 . _ -)");
        set = options.name;
    } else if (table.name) {
        if (!isIdSafe(*table.name))
            throwInput(table.where, "name", "'" + *table.name + "' is not a set name (a-z 0-9 . _ -)");
        set = *table.name;
    } else {
        set = sanitizeLabel(options.table.stem().string());
        if (set.empty()) throwInput(table.where, "", "cannot make a set name of the file name; give --name");
    }
    return set;
}

// What the rows checked so far hold, for the checks across rows.
struct RowsSeen {
    std::map<std::string, int> idLines;
    std::map<std::string, int> referenceLines;                   // block → line of its reference
    std::map<std::string, std::tuple<int, int, int>> blockSizes; // block → width, height, line
};

// Depth and mask AOVs (for the metrics' skin and band scores), with the camera they need.
void checkAovs(const Table& table, const Row& row, const fs::path& base, Checked& c) {
    std::error_code ec;
    std::string reason;
    if (row.depth.has_value() != row.mask.has_value())
        fail(table, row, row.depth ? "mask" : "depth", "depth and mask images are given together");
    if (row.depth) {
        for (const char* key : kCameraColumns)
            if (!row.camera.count(key))
                fail(table, row, key,
                     "a depth image needs f_px, mm_per_unit and sss_radius_mm (the camera and kernel of the "
                     "metrics' bands)");
        for (const auto& [key, aov] : {std::pair{"depth", &c.depth}, std::pair{"mask", &c.mask}}) {
            const std::string& name = key == std::string("depth") ? *row.depth : *row.mask;
            *aov = fs::path(name).is_absolute() ? fs::path(name) : base / name;
            if (!fs::is_regular_file(*aov, ec))
                fail(table, row, key, "'" + name + "' not found (" + aov->string() + ")");
            std::optional<Pixels> plane = readPixels(*aov, reason);
            if (!plane) fail(table, row, key, "'" + name + "' is not a readable image (" + reason + ")");
            if (plane->width != c.width || plane->height != c.height)
                fail(table, row, key,
                     "'" + name + "' is " + std::to_string(plane->width) + "x" + std::to_string(plane->height) +
                         ", its image '" + row.file + "' " + std::to_string(c.width) + "x" + std::to_string(c.height));
        }
    }
    for (const auto& [key, value] : row.camera) {
        if (!row.depth) fail(table, row, key, "applies only with depth and mask images");
        if (!(value > 0.0)) fail(table, row, key, std::to_string(value) + " is not a positive number");
    }
}

// Every check of one row, its image and AOVs read, against the rows before it.
Checked checkRow(const Table& table, const Row& row, const std::string& set, const fs::path& base, RowsSeen& seen) {
    Checked c;
    c.row = &row;
    if (row.file.empty()) fail(table, row, "file", "no image file given");
    if (row.id) {
        if (!isIdSafe(*row.id)) fail(table, row, "id", "'" + *row.id + "' is not an id (a-z 0-9 . _ -)");
        c.id = *row.id;
    } else {
        c.id = sanitizeLabel(fs::path(row.file).stem().string());
        if (c.id.empty()) fail(table, row, "file", "cannot make an id of '" + row.file + "'; give an id");
    }
    if (auto it = seen.idLines.find(c.id); it != seen.idLines.end())
        fail(table, row, row.id ? "id" : "file",
             "the id '" + c.id + "' is also the id of line " + std::to_string(it->second) +
                 (row.id ? "" : " (give an id column)"));
    seen.idLines[c.id] = lineOf(row, row.id ? "id" : "file");
    c.block = row.block.value_or(set);
    if (row.reference) {
        if (auto it = seen.referenceLines.find(c.block); it != seen.referenceLines.end())
            fail(table, row, "reference",
                 "block '" + c.block + "' already has its reference on line " + std::to_string(it->second));
        seen.referenceLines[c.block] = lineOf(row, "reference");
    }
    if (row.encoding && *row.encoding != "srgb" && *row.encoding != "linear")
        fail(table, row, "encoding", "'" + *row.encoding + "' is not one of srgb, linear");

    c.path = fs::path(row.file).is_absolute() ? fs::path(row.file) : base / row.file;
    std::error_code ec;
    if (!fs::is_regular_file(c.path, ec))
        fail(table, row, "file", "'" + row.file + "' not found (" + c.path.string() + ")");
    std::string reason;
    std::optional<Pixels> pixels = readPixels(c.path, reason);
    if (!pixels) fail(table, row, "file", "'" + row.file + "' is not a readable image (" + reason + ")");
    c.linear = row.encoding ? *row.encoding == "linear" : pixels->floatingPoint;
    if (row.exposureEv && !c.linear)
        fail(table, row, "exposure_ev", "applies to linear images only ('" + row.file + "' is sRGB)");
    c.exposureEv = row.exposureEv.value_or(0.0);
    c.width = pixels->width;
    c.height = pixels->height;
    if (auto it = seen.blockSizes.find(c.block); it != seen.blockSizes.end()) {
        auto [w, h, line] = it->second;
        if (w != c.width || h != c.height)
            fail(table, row, "file",
                 "'" + row.file + "' is " + std::to_string(c.width) + "x" + std::to_string(c.height) + ", block '" +
                     c.block + "' holds " + std::to_string(w) + "x" + std::to_string(h) + " images (line " +
                     std::to_string(line) + "); crop or scale them alike first");
    } else {
        seen.blockSizes[c.block] = {c.width, c.height, lineOf(row, "file")};
    }
    c.originalSha256 = sha256File(c.path);

    checkAovs(table, row, base, c);
    return c;
}

// The set's manifest before its stimuli: name, table, factors and ids.
Manifest importManifest(const ImportOptions& options, const Table& table, const std::string& set,
                        const std::vector<Checked>& checked) {
    Manifest manifest;
    manifest.set = set;
    manifest.description = table.description;
    manifest.specFile = options.table.filename().string();
    manifest.specSha256 = sha256Hex(table.text);
    manifest.renderer = {"imported", "", version()};
    for (const std::string& factor : table.factors) {
        nlohmann::json levels = nlohmann::json::array();
        std::vector<std::string> seen;
        for (const Row& row : table.rows) {
            auto it = row.factors.find(factor);
            if (it == row.factors.end() || std::find(seen.begin(), seen.end(), it->second) != seen.end()) continue;
            seen.push_back(it->second);
            std::string label = sanitizeLabel(it->second);
            levels.push_back({{"value", it->second}, {"label", label.empty() ? it->second : label}});
        }
        manifest.factors.push_back({{"name", factor}, {"key", factor}, {"levels", levels}});
    }
    for (const Checked& c : checked) manifest.setIds.push_back(c.id);
    return manifest;
}

// The stimulus's EXR (linear, with its AOVs) and PNG (display) in the set's folder.
void writeStimulusImages(const fs::path& dir, const Checked& c) {
    std::string reason;
    std::optional<Pixels> pixels = readPixels(c.path, reason);
    if (!pixels) throw RuntimeError(c.path.string() + ": cannot read the image any more (" + reason + ")");
    // Display values (8-bit sRGB PNG) and linear values (float EXR) of the same pixels.
    std::vector<float> display(pixels->rgb.size()), linear(pixels->rgb.size());
    const float gain = static_cast<float>(std::exp2(c.exposureEv));
    for (size_t i = 0; i < pixels->rgb.size(); ++i) {
        const float v = pixels->rgb[i];
        if (c.linear) {
            linear[i] = v * gain;
            display[i] = linearToSrgb(linear[i]);
        } else {
            display[i] = std::clamp(v, 0.0f, 1.0f);
            linear[i] = srgbToLinear(display[i]);
        }
    }
    std::vector<std::string> channels = {"R", "G", "B"};
    if (!c.depth.empty()) { // R, G, B, depth.Z, mask.Y (contract 1)
        std::optional<Pixels> depth = readPixels(c.depth, reason, "depth.Z"),
                              mask = readPixels(c.mask, reason, "mask.Y");
        if (!depth || !mask) throw RuntimeError(c.path.string() + ": cannot read its AOVs any more (" + reason + ")");
        std::vector<float> all;
        all.reserve(linear.size() / 3 * 5);
        for (size_t i = 0; i < depth->plane.size(); ++i)
            all.insert(all.end(), {linear[i * 3], linear[i * 3 + 1], linear[i * 3 + 2], depth->plane[i],
                                   std::clamp(mask->plane[i], 0.0f, 1.0f)});
        linear = std::move(all);
        channels.insert(channels.end(), {"depth.Z", "mask.Y"});
    }
    AtomicOutput exr(dir / exrRelativePath(c.id));
    AtomicOutput png(dir / pngRelativePath(c.id));
    writeImage(exr.tempPath(), c.width, c.height, OIIO::TypeDesc::FLOAT, linear, channels,
               {{"skinlab:version", version()}, {"skinlab:imported_from", c.row->file}}, c.row->camera);
    writeImage(png.tempPath(), c.width, c.height, OIIO::TypeDesc::UINT8, display, {"R", "G", "B"}, {});
    exr.commit();
    png.commit();
}

// The stimulus's manifest entry.
formats::ManifestEntry stimulusEntry(const fs::path& dir, const Table& table, const Manifest& manifest,
                                     const Checked& c) {
    nlohmann::json factors = nlohmann::json::object();
    for (const std::string& f : table.factors)
        if (auto it = c.row->factors.find(f); it != c.row->factors.end()) factors[f] = it->second;
    nlohmann::json provenance = {
        {"kind", "imported"},         {"original", c.row->file}, {"original_sha256", c.originalSha256},
        {"table", manifest.specFile}, {"line", c.row->line},     {"encoding", c.linear ? "linear" : "srgb"}};
    if (c.linear) provenance["exposure_ev"] = c.exposureEv;
    if (c.row->depth) {
        provenance["depth"] = *c.row->depth;
        provenance["depth_sha256"] = sha256File(c.depth);
        provenance["mask"] = *c.row->mask;
        provenance["mask_sha256"] = sha256File(c.mask);
        for (const auto& [key, value] : c.row->camera) provenance[key] = value;
    }
    formats::ManifestEntry entry;
    entry.id = c.id;
    entry.files = {exrRelativePath(c.id), pngRelativePath(c.id)};
    entry.sha256 = {sha256File(dir / entry.files.exr), sha256File(dir / entry.files.png)};
    entry.factors = factors;
    entry.block = c.block;
    entry.reference = c.row->reference;
    entry.width = c.width;
    entry.height = c.height;
    entry.scene = factors.value("scene", "");
    entry.provenance = provenance;
    return entry;
}

} // namespace

ImportSummary importStimuli(const ImportOptions& options) {
    const Table table = readImportTable(options);

    const std::string set = importSetName(options, table);
    const fs::path base = options.images.empty() ? options.table.parent_path() : options.images;
    if (!options.images.empty() && !fs::is_directory(options.images))
        throwInput("--images", "", options.images.string() + " is not a folder");

    // Every check, every image read, before anything is written.
    std::vector<Checked> checked;
    RowsSeen seen;
    for (const Row& row : table.rows) checked.push_back(checkRow(table, row, set, base, seen));

    Manifest manifest = importManifest(options, table, set, checked);

    const fs::path& dir = options.outputDir;
    claimOutputFolder(dir, set, std::nullopt);
    ensureDirectory(dir);
    OutputFolderLock lock(dir);
    claimOutputFolder(dir, set, std::nullopt);
    ensureDirectory(dir / "exr");
    ensureDirectory(dir / "png");
    for (const Checked& c : checked) {
        writeStimulusImages(dir, c);
        manifest.stimuli.push_back(stimulusEntry(dir, table, manifest, c));
    }
    tidyOutputFolder(dir, manifest.setIds);
    manifest.complete = true;
    writeManifest(dir, manifest);

    ImportSummary summary;
    if (options.predict) { // predicted visibility against each block's reference, as in a built set
        PredictionOptions prediction;
        prediction.display = options.display;
        const PredictionSummary predicted = predictStimuli(dir, manifest, prediction);
        if (predicted.predicted > 0) writeManifest(dir, manifest);
        summary.predictions = predictionLines(predicted, prediction);
    }
    summary.set = set;
    summary.stimuli = manifest.stimuli.size();
    summary.blocks = seen.blockSizes.size();
    summary.manifest = dir / kManifestFile;
    if (options.contactSheet) summary.contactHtml = writeContactSheet(dir, manifest).html;
    return summary;
}

} // namespace skinlab::stimuli
