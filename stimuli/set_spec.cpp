#include "stimuli/set_spec.h"

#include "common/error.h"
#include "common/files.h"
#include "common/hash.h"
#include "common/spec.h"
#include "stimuli/naming.h"

#include <algorithm>
#include <limits>
#include <set>
#include <stdexcept>

namespace skinlab::stimuli {

namespace fs = std::filesystem;

std::string sceneKeyOf(const std::string& factorName) {
    if (factorName == "method") return "sss.method";
    if (factorName == "view") return "camera.view";
    if (factorName == "scene") return "";
    return factorName;
}

const std::vector<std::string>& alwaysFixedKeys() {
    // Resolution, exposure and tone mapping change how every pixel is displayed: varying them inside a set would
    // favour some conditions by brightness or sharpness rather than by the factor under test.
    static const std::vector<std::string> keys = {"render.width", "render.height", "render.exposure_ev", "tone_map"};
    return keys;
}

namespace {

// True when one dotted key is the other or lies below it ("render" and "render.width").
bool keysOverlap(const std::string& a, const std::string& b) {
    if (a == b) return true;
    if (a.size() < b.size()) return b.compare(0, a.size(), a) == 0 && b[a.size()] == '.';
    return a.compare(0, b.size(), b) == 0 && a[b.size()] == '.';
}

bool isKeyName(const std::string& name) {
    if (name.empty() || name.front() == '.' || name.back() == '.') return false;
    for (size_t i = 0; i < name.size(); ++i) {
        char c = name[i];
        bool ok = (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || (c == '.' && name[i - 1] != '.');
        if (!ok) return false;
    }
    return true;
}

void flatten(const toml::table& table, const std::string& prefix,
             std::vector<std::pair<std::string, const toml::node*>>& out) {
    for (auto&& [k, v] : table) {
        std::string key = prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
        if (auto* t = v.as_table()) flatten(*t, key, out);
        else out.emplace_back(key, &v);
    }
}

class Reader {
public:
    Reader(const toml::table& root, std::string fileName, fs::path specFile)
        : root_(root), reader_(root, fileName), fileName_(std::move(fileName)), specFile_(std::move(specFile)) {}

    SetSpec read() {
        SetSpec spec;
        spec.file = specFile_;
        spec.fileName = fileName_;
        SpecReader set = reader_.table("set");
        spec.name = set.requiredString("name");
        if (!isIdSafe(spec.name)) set.fail("name", "'" + spec.name + "' is not a valid set name (use a-z 0-9 . _ -)");
        spec.description = set.string("description", "");
        if (set.has("seed")) spec.seed = set.integer("seed", 0, 0, std::numeric_limits<std::int64_t>::max());
        spec.idTemplate = set.string("id", "");
        bool blockGiven = set.has("block");
        spec.blockFactors = set.strings("block", {"scene", "view"});

        readFixed(spec);

        // The scene: one fixed scene in set.scene, or a factor named "scene".
        bool sceneFixed = set.has("scene");
        if (sceneFixed) {
            std::string scene = set.string("scene", "");
            Factor factor{"scene", "", {sceneLevel(scene, set, "scene")}};
            spec.factors.push_back(std::move(factor));
        }
        std::vector<SpecReader> factorReaders = reader_.tables("factor");
        for (size_t i = 0; i < factorReaders.size(); ++i) {
            Factor factor = readFactor(factorReaders[i], spec);
            if (factor.name == "scene") {
                if (sceneFixed)
                    factorReaders[i].fail("name", "the scene is both fixed (set.scene) and a factor; keep one");
                spec.factors.insert(spec.factors.begin(), std::move(factor));
                sceneFixed = true;
            } else {
                spec.factors.push_back(std::move(factor));
            }
        }
        if (!sceneFixed)
            set.fail("scene", "missing (a scene \"builtin:NAME\" or scene spec path, or a [[factor]] named scene)");

        spec.excludes = readSelections("exclude", spec, true);
        spec.includes = readSelections("include", spec, false);
        spec.references = readSelections("reference", spec, false);

        checkTemplateAndBlocks(spec, set, blockGiven);
        readCrops(spec);
        reader_.finish();
        return spec;
    }

private:
    Level sceneLevel(const std::string& scene, const SpecReader& where, const std::string& key) {
        Level level;
        level.value = scene;
        level.json = scene;
        level.label = sceneLabel(scene);
        if (scene.rfind("builtin:", 0) == 0) {
            level.overrideText = scene;
        } else {
            fs::path path = scene;
            if (path.is_relative()) path = specFile_.parent_path() / path;
            if (!fs::exists(path)) where.fail(key, "scene file '" + path.lexically_normal().string() + "' not found");
            level.overrideText = fs::absolute(path).lexically_normal().string();
        }
        if (level.label.empty()) where.fail(key, "cannot make an id label from scene '" + scene + "'");
        return level;
    }

    Level valueLevel(const toml::node& node, const std::string& key, size_t index, const SpecReader& where,
                     const std::string& field) {
        Level level;
        try {
            level.overrideText = tomlValueText(node);
        } catch (const std::invalid_argument& e) {
            where.fail(field, e.what());
        }
        level.json = tomlToJson(node);
        std::string component = lastKeyComponent(key);
        if (auto* s = node.as_string()) {
            level.value = s->get();
            level.label = sanitizeLabel(s->get());
        } else if (auto* b = node.as_boolean()) {
            level.value = b->get() ? "true" : "false";
            // "transmittance.enabled = true" reads better as "transmittance" than as "enabled".
            std::string subject = component;
            if ((component == "enabled" || component == "enable") && key.find('.') != std::string::npos)
                subject = lastKeyComponent(key.substr(0, key.rfind('.')));
            level.label = b->get() ? subject : "no-" + subject;
        } else if (node.is_array()) {
            level.value = level.overrideText;
            level.label = component + "-" + std::to_string(index + 1);
        } else {
            level.value = level.overrideText;
            level.label = sanitizeLabel(component + "-" + level.overrideText);
        }
        if (level.label.empty()) where.fail(field, "cannot make an id label from '" + level.value + "'; give labels");
        return level;
    }

    // An integer in [min, max] at `field` (a full key path for messages).
    std::int64_t presentationInteger(const toml::node& node, const std::string& field, std::int64_t min,
                                     std::int64_t max) {
        auto* value = node.as_integer();
        if (!value) throwInput(fileName_, field, "expected an integer, got " + describeNode(node));
        const std::int64_t v = value->get();
        if (v < min || v > max)
            throwInput(fileName_, field,
                       std::to_string(v) + " is out of range [" + std::to_string(min) + ", " + std::to_string(max) +
                           "]");
        return v;
    }

    // crop = { x, y, width, height }: pixels of the render; whether it lies inside the frame is checked against
    // the resolved render size (build.cpp), since the size may come from the scene.
    PresentationMethod presentationMethod(const toml::node& node, const std::string& field) {
        auto* value = node.as_string();
        if (!value) throwInput(fileName_, field, "expected \"native\" or \"replicate\", got " + describeNode(node));
        if (value->get() == "native") return PresentationMethod::native;
        if (value->get() == "replicate") return PresentationMethod::replicate;
        throwInput(fileName_, field,
                   "'" + value->get() +
                       "' is not a presentation (native: the crop rendered at the presented size; "
                       "replicate: nearest-neighbour magnification)");
    }

    CropRect readCrop(const toml::node& node, const std::string& field) {
        auto* table = node.as_table();
        if (!table) throwInput(fileName_, field, "expected a table { x, y, width, height }, got " + describeNode(node));
        for (auto&& [k, v] : *table) {
            const std::string key(k.str());
            if (key != "x" && key != "y" && key != "width" && key != "height")
                throwInput(fileName_, field + "." + key, "unknown key (a crop has x, y, width, height)");
        }
        CropRect crop;
        const std::pair<const char*, int*> parts[] = {
            {"x", &crop.x}, {"y", &crop.y}, {"width", &crop.width}, {"height", &crop.height}};
        for (const auto& [key, target] : parts) {
            const toml::node* value = table->get(key);
            if (!value) throwInput(fileName_, field + "." + key, "missing (a crop has x, y, width, height in pixels)");
            const bool size = key[0] == 'w' || key[0] == 'h';
            *target = static_cast<int>(presentationInteger(*value, field + "." + key, size ? 1 : 0, 16384));
        }
        return crop;
    }

    void readFixed(SetSpec& spec) {
        const toml::node* fixed = reader_.raw("fixed");
        if (!fixed) return;
        if (!fixed->is_table()) reader_.fail("fixed", "expected a table, got " + describeNode(*fixed));
        // Presentation keys (applied to the rendered image, not scene keys).
        toml::table scene = *fixed->as_table();
        if (const toml::node* crop = scene.get("crop")) spec.presentation.crop = readCrop(*crop, "fixed.crop");
        if (const toml::node* m = scene.get("magnification"))
            spec.presentation.magnification =
                static_cast<int>(presentationInteger(*m, "fixed.magnification", 1, kMaxMagnification));
        if (const toml::node* method = scene.get("presentation"))
            spec.presentation.method = presentationMethod(*method, "fixed.presentation");
        scene.erase("crop");
        scene.erase("magnification");
        scene.erase("presentation");
        std::vector<std::pair<std::string, const toml::node*>> leaves;
        flatten(scene, "", leaves);
        for (auto& [key, node] : leaves) {
            if (key == "scene") reader_.fail("fixed.scene", "the scene is set by set.scene or a factor, not [fixed]");
            FixedParameter parameter;
            parameter.key = key;
            parameter.level = valueLevel(*node, key, 0, reader_, "fixed." + key);
            spec.fixed.push_back(std::move(parameter));
        }
        std::sort(spec.fixed.begin(), spec.fixed.end(),
                  [](const FixedParameter& a, const FixedParameter& b) { return a.key < b.key; });
    }

    // A factor or extra key may not touch a parameter held fixed.
    void checkNotFixed(const std::string& key, const SetSpec& spec, const SpecReader& where, const std::string& field) {
        for (const auto& fixed : spec.fixed)
            if (keysOverlap(key, fixed.key))
                where.fail(field, "'" + key + "' conflicts with the fixed parameter fixed." + fixed.key +
                                      " (held the same for every stimulus of the set)");
        for (const auto& always : alwaysFixedKeys())
            if (keysOverlap(key, always))
                where.fail(field, "'" + key + "' is held fixed across every stimulus set (set " + always +
                                      " in [fixed]); it cannot vary");
    }

    Factor readFactor(const SpecReader& reader, const SetSpec& spec) {
        Factor factor;
        factor.name = reader.requiredString("name");
        if (!isKeyName(factor.name))
            reader.fail("name", "'" + factor.name +
                                    "' is not a factor name (a scene key like sss.samples, or "
                                    "scene, method, view)");
        factor.key = sceneKeyOf(factor.name);
        for (const auto& other : spec.factors)
            if (factor.name == "scene") break; // a second scene is reported by read()
            else if (other.name == factor.name || (!factor.key.empty() && keysOverlap(other.key, factor.key)))
                reader.fail("name", "'" + factor.name + "' varies the same scene key as factor '" + other.name + "'");
        if (!factor.key.empty()) checkNotFixed(factor.key, spec, reader, "name");

        const toml::node* levels = reader.raw("levels");
        if (!levels) reader.fail("levels", "missing (an array of levels)");
        auto* array = levels->as_array();
        if (!array) reader.fail("levels", "expected an array of levels, got " + describeNode(*levels));
        if (array->empty()) reader.fail("levels", "factor '" + factor.name + "' has no levels");
        for (size_t i = 0; i < array->size(); ++i) {
            const toml::node& node = *array->get(i);
            std::string field = "levels[" + std::to_string(i) + "]";
            if (factor.name == "scene") {
                if (!node.is_string()) reader.fail(field, "expected a scene (string), got " + describeNode(node));
                factor.levels.push_back(sceneLevel(node.as_string()->get(), reader, field));
            } else {
                factor.levels.push_back(valueLevel(node, factor.key, i, reader, field));
            }
            for (size_t j = 0; j < i; ++j)
                if (factor.levels[j].overrideText == factor.levels.back().overrideText)
                    reader.fail(field, "'" + factor.levels.back().value + "' is listed twice");
        }
        std::vector<std::string> labels = reader.strings("labels", {});
        if (reader.has("labels")) {
            if (labels.size() != factor.levels.size())
                reader.fail("labels", std::to_string(labels.size()) + " labels for " +
                                          std::to_string(factor.levels.size()) + " levels");
            for (size_t i = 0; i < labels.size(); ++i) {
                if (!isIdSafe(labels[i]))
                    reader.fail("labels", "'" + labels[i] + "' is not a valid label (use a-z 0-9 . _ -)");
                factor.levels[i].label = labels[i];
            }
        }
        for (size_t i = 0; i < factor.levels.size(); ++i)
            for (size_t j = 0; j < i; ++j)
                if (factor.levels[i].label == factor.levels[j].label)
                    reader.fail(reader.has("labels") ? "labels" : "levels",
                                "levels '" + factor.levels[j].value + "' and '" + factor.levels[i].value +
                                    "' have the same label '" + factor.levels[i].label + "'; give labels");
        return factor;
    }

    // [[exclude]] / [[include]] / [[reference]]: keys name factors (or, for include/reference, extra scene keys);
    // values are one level or an array of levels.
    std::vector<Selection> readSelections(const std::string& key, const SetSpec& spec, bool factorsOnly) {
        std::vector<SpecReader> readers = reader_.tables(key);
        std::vector<Selection> out;
        const toml::array* array = root_.get(key) ? root_.get(key)->as_array() : nullptr;
        for (size_t i = 0; i < readers.size(); ++i) {
            const SpecReader& reader = readers[i];
            const toml::table& table = *array->get(i)->as_table();
            Selection selection;
            selection.where = key + "[" + std::to_string(i) + "]";
            for (auto&& [k, v] : table) reader.raw(k.str());
            std::vector<std::pair<std::string, const toml::node*>> leaves;
            flatten(table, "", leaves);
            if (leaves.empty())
                throwInput(reader.file(), selection.where, "is empty (name at least one factor and its level)");
            for (auto& [name, node] : leaves) {
                const Factor* factor = nullptr;
                for (const auto& f : spec.factors)
                    if (f.name == name || (!f.key.empty() && f.key == sceneKeyOf(name))) factor = &f;
                if (!factor && factorsOnly) reader.fail(name, "'" + name + "' is not a factor of this set");
                if (!factor && name == "scene") reader.fail(name, "the scene can only vary as a factor");
                if (!factor) {
                    if (!isKeyName(name)) reader.fail(name, "'" + name + "' is not a scene key");
                    checkNotFixed(sceneKeyOf(name), spec, reader, name);
                }
                std::string canonical = factor ? factor->name : name;
                std::vector<const toml::node*> values;
                if (auto* a = node->as_array()) {
                    if (a->empty()) reader.fail(name, "no levels given");
                    for (size_t j = 0; j < a->size(); ++j) values.push_back(a->get(j));
                } else {
                    values.push_back(node);
                }
                std::vector<Level> levels;
                for (size_t j = 0; j < values.size(); ++j)
                    levels.push_back(selectionLevel(*values[j], factor, name, reader, factorsOnly));
                selection.levels.emplace_back(canonical, std::move(levels));
            }
            out.push_back(std::move(selection));
        }
        return out;
    }

    Level selectionLevel(const toml::node& node, const Factor* factor, const std::string& name,
                         const SpecReader& reader, bool mustBeLevel) {
        if (factor) {
            // A level of the factor, written as its value or its label.
            std::string text;
            try {
                text = tomlValueText(node);
            } catch (const std::invalid_argument& e) {
                reader.fail(name, e.what());
            }
            for (const auto& level : factor->levels) {
                bool sameValue = factor->name == "scene" ? (node.is_string() && node.as_string()->get() == level.value)
                                                         : level.overrideText == text;
                bool sameLabel = node.is_string() && node.as_string()->get() == level.label;
                if (sameValue || sameLabel) return level;
            }
            std::string shown = node.is_string() ? node.as_string()->get() : text;
            if (mustBeLevel) reader.fail(name, "'" + shown + "' is not a level of factor '" + factor->name + "'");
            if (factor->name == "scene") {
                if (!node.is_string()) reader.fail(name, "expected a scene (string), got " + describeNode(node));
                return sceneLevel(node.as_string()->get(), reader, name);
            }
            return valueLevel(node, factor->key, factor->levels.size(), reader, name);
        }
        return valueLevel(node, sceneKeyOf(name), 0, reader, name);
    }

    // [[crop]]: block-factor levels (one level or a list each) plus crop = {...} and/or magnification.
    void readCrops(SetSpec& spec) {
        const toml::node* node = reader_.raw("crop");
        if (!node) return;
        auto* array = node->as_array();
        if (!array || !array->is_array_of_tables())
            reader_.fail("crop", "expected [[crop]] tables (block levels with crop = { x, y, width, height })");
        for (size_t i = 0; i < array->size(); ++i) {
            const toml::table& table = *array->get(i)->as_table();
            const std::string where = "crop[" + std::to_string(i) + "]";
            CropRule rule;
            rule.selection.where = where;
            for (auto&& [k, v] : table) {
                const std::string name(k.str());
                const std::string field = where + "." + name;
                if (name == "crop") {
                    rule.crop = readCrop(v, field);
                    continue;
                }
                if (name == "magnification") {
                    rule.magnification = static_cast<int>(presentationInteger(v, field, 1, kMaxMagnification));
                    continue;
                }
                if (name == "presentation") {
                    rule.method = presentationMethod(v, field);
                    continue;
                }
                const Factor* factor = nullptr;
                for (const auto& f : spec.factors)
                    if (f.name == name || (!f.key.empty() && f.key == sceneKeyOf(name))) factor = &f;
                const bool block = factor && std::find(spec.blockFactors.begin(), spec.blockFactors.end(),
                                                       factor->name) != spec.blockFactors.end();
                if (!block)
                    throwInput(fileName_, field,
                               "'" + name +
                                   "' is not a block factor of this set (a crop applies to whole blocks, so that "
                                   "every condition of a block is presented alike)");
                std::vector<const toml::node*> values;
                if (auto* a = v.as_array()) {
                    if (a->empty()) throwInput(fileName_, field, "no levels given");
                    for (size_t j = 0; j < a->size(); ++j) values.push_back(a->get(j));
                } else {
                    values.push_back(&v);
                }
                SpecReader reader(table, fileName_, where);
                std::vector<Level> levels;
                for (const toml::node* value : values)
                    levels.push_back(selectionLevel(*value, factor, name, reader, true));
                rule.selection.levels.emplace_back(factor->name, std::move(levels));
            }
            if (!rule.crop && !rule.magnification && !rule.method)
                throwInput(fileName_, where,
                           "gives none of crop = { x, y, width, height }, magnification, presentation");
            spec.crops.push_back(std::move(rule));
        }
    }

    void checkTemplateAndBlocks(SetSpec& spec, const SpecReader& set, bool blockGiven) {
        auto isFactor = [&](const std::string& name) {
            return std::any_of(spec.factors.begin(), spec.factors.end(),
                               [&](const Factor& f) { return f.name == name; });
        };
        auto isFixed = [&](const std::string& name) {
            return std::any_of(spec.fixed.begin(), spec.fixed.end(),
                               [&](const FixedParameter& p) { return p.key == sceneKeyOf(name); });
        };
        if (!spec.idTemplate.empty()) {
            NamingTemplate parsed;
            try {
                parsed = parseNamingTemplate(spec.idTemplate);
            } catch (const std::invalid_argument& e) {
                set.fail("id", std::string("'") + spec.idTemplate + "': " + e.what());
            }
            std::set<std::string> extraKeys;
            for (const auto* group : {&spec.includes, &spec.references})
                for (const auto& selection : *group)
                    for (const auto& [name, levels] : selection.levels) extraKeys.insert(name);
            for (const auto& part : parsed.parts)
                if (part.placeholder && !isFactor(part.text) && !extraKeys.count(part.text))
                    set.fail("id", "placeholder {" + part.text + "} is not a factor of this set");
        }
        std::vector<std::string> blocks;
        for (const auto& name : spec.blockFactors) {
            if (isFactor(name) || isFixed(name)) blocks.push_back(name);
            else if (blockGiven) set.fail("block", "'" + name + "' is neither a factor nor a fixed parameter");
        }
        spec.blockFactors = blocks;
    }

    const toml::table& root_;
    SpecReader reader_;
    std::string fileName_;
    fs::path specFile_;
};

SetSpec readParsed(toml::table root, const std::string& bytes, const fs::path& file,
                   const std::vector<std::string>& overrides) {
    std::string hashInput = bytes;
    for (const auto& assignment : overrides) {
        applyOverride(root, assignment, "--set");
        hashInput += "\n--set " + assignment;
    }
    Reader reader(root, file.string(), file);
    SetSpec spec = reader.read();
    spec.sha256 = sha256Hex(hashInput);
    return spec;
}

} // namespace

SetSpec readSetSpec(const fs::path& file, const std::vector<std::string>& overrides) {
    toml::table root = parseTomlFile(file);
    return readParsed(std::move(root), readFile(file), file, overrides);
}

SetSpec readSetSpecString(std::string_view text, const fs::path& file, const std::vector<std::string>& overrides) {
    toml::table root = parseTomlString(text, file.string());
    return readParsed(std::move(root), std::string(text), file, overrides);
}

} // namespace skinlab::stimuli
