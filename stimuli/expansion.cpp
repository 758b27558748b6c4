#include "stimuli/expansion.h"

#include "common/error.h"
#include "renderer/sss/sss_params.h"
#include "stimuli/naming.h"

#include <algorithm>
#include <charconv>
#include <map>
#include <optional>

namespace skinlab::stimuli {

namespace {

using Assignment = std::vector<std::pair<std::string, Level>>; // factor or extra key → level

const Level* find(const Assignment& assignment, const std::string& name) {
    for (const auto& [n, level] : assignment)
        if (n == name) return &level;
    return nullptr;
}

bool matches(const Assignment& combination, const Selection& exclude) {
    for (const auto& [name, levels] : exclude.levels) {
        const Level* level = find(combination, name);
        if (!level) return false;
        bool any = std::any_of(levels.begin(), levels.end(),
                               [&](const Level& l) { return l.overrideText == level->overrideText; });
        if (!any) return false;
    }
    return true;
}

// Every combination of the given factors' levels (the last factor varies fastest).
std::vector<Assignment> cartesian(const std::vector<const Factor*>& factors) {
    std::vector<Assignment> out{Assignment{}};
    for (const Factor* factor : factors) {
        std::vector<Assignment> next;
        for (const auto& partial : out)
            for (const auto& level : factor->levels) {
                Assignment a = partial;
                a.emplace_back(factor->name, level);
                next.push_back(std::move(a));
            }
        out = std::move(next);
    }
    return out;
}

class Expander {
public:
    explicit Expander(const SetSpec& spec) : spec_(spec) {
        if (!spec.idTemplate.empty()) template_ = parseNamingTemplate(spec.idTemplate);
    }

    std::vector<Stimulus> run() {
        std::vector<const Factor*> all;
        for (const auto& f : spec_.factors) all.push_back(&f);
        for (const auto& combination : cartesian(all)) {
            bool excluded = std::any_of(spec_.excludes.begin(), spec_.excludes.end(),
                                        [&](const Selection& e) { return matches(combination, e); });
            if (!excluded) add(combination, false, "factor");
        }
        if (out_.empty()) {
            std::string where = spec_.excludes.empty() ? "factor" : "exclude";
            if (spec_.includes.empty() && spec_.references.empty())
                throwInput(spec_.fileName, where, "the factorial is empty (every combination is excluded)");
        }
        for (const auto& include : spec_.includes) addSelection(include, false);
        for (const auto& reference : spec_.references) addSelection(reference, true);
        if (out_.empty()) throwInput(spec_.fileName, "factor", "the set is empty (no stimulus to render)");
        return std::move(out_);
    }

private:
    // An include/reference names some factors (and maybe extra keys); the block factors it leaves out are
    // expanded over all their levels so that every block gets one; other factors are left at the scene default.
    void addSelection(const Selection& selection, bool reference) {
        std::vector<Factor> named; // one factor per named key with the selection's levels
        for (const auto& [name, levels] : selection.levels) named.push_back(Factor{name, sceneKeyOf(name), levels});
        std::vector<const Factor*> factors;
        for (const auto& f : spec_.factors) {
            auto it = std::find_if(named.begin(), named.end(), [&](const Factor& n) { return n.name == f.name; });
            bool isBlock =
                std::find(spec_.blockFactors.begin(), spec_.blockFactors.end(), f.name) != spec_.blockFactors.end();
            if (it != named.end()) factors.push_back(&*it);
            else if (isBlock || f.name == "scene") factors.push_back(&f);
        }
        for (const auto& n : named) // extra scene keys, after the factors
            if (std::none_of(spec_.factors.begin(), spec_.factors.end(),
                             [&](const Factor& f) { return f.name == n.name; }))
                factors.push_back(&n);
        for (const auto& combination : cartesian(factors)) add(combination, reference, selection.where);
    }

    std::string label(const Assignment& combination, const std::string& name) const {
        const Level* level = find(combination, name);
        return level ? level->label : "";
    }

    std::string makeId(const Assignment& combination, bool reference) const {
        std::vector<std::string> pieces;
        if (!template_) {
            // Default: every level's label in factor order; a reference without its own label is marked "ref".
            for (const auto& [name, level] : combination) pieces.push_back(level.label);
            std::string id;
            for (const auto& p : pieces) id += (id.empty() ? "" : "-") + p;
            return reference && id.find("ref") == std::string::npos ? id + "-ref" : id;
        }
        // Template: placeholders of absent factors vanish with one neighbouring separator.
        std::string id;
        for (const auto& part : template_->parts) {
            if (!part.placeholder) {
                id += part.text;
                continue;
            }
            std::string l = label(combination, part.text);
            if (l.empty()) {
                while (!id.empty() && (id.back() == '-' || id.back() == '_' || id.back() == '.')) id.pop_back();
            } else {
                id += l;
            }
        }
        while (!id.empty() && (id.front() == '-' || id.front() == '_' || id.front() == '.')) id.erase(id.begin());
        while (!id.empty() && (id.back() == '-' || id.back() == '_' || id.back() == '.')) id.pop_back();
        return id;
    }

    std::string makeBlock(const Assignment& combination) const {
        std::string block;
        for (const auto& name : spec_.blockFactors) {
            std::string value;
            if (const Level* level = find(combination, name)) {
                value = level->value;
                if (name == "scene" && value.rfind("builtin:", 0) != 0) value = level->label;
            } else {
                for (const auto& p : spec_.fixed)
                    if (p.key == sceneKeyOf(name)) value = p.level.value;
            }
            if (!value.empty()) block += (block.empty() ? "" : "/") + value;
        }
        return block;
    }

    // The SSS method a stimulus sets (a factor, include or reference level, or [fixed]); nullptr when it keeps the
    // scene's method, which the scene file decides (its reader then checks the keys).
    const renderer::sss::MethodInfo* methodOf(const Assignment& combination) const {
        std::string text;
        for (const auto& p : spec_.fixed)
            if (p.key == "sss.method") text = p.level.overrideText;
        for (const auto& [name, level] : combination)
            if (sceneKeyOf(name) == "sss.method") text = level.overrideText;
        if (text.size() >= 2 && (text.front() == '"' || text.front() == '\'')) text = text.substr(1, text.size() - 2);
        return text.empty() ? nullptr : renderer::sss::findMethod(text);
    }

    // Whether the method reads scene key `key`; keys outside [sss] and unknown keys are left to the scene reader.
    static bool methodReads(const renderer::sss::MethodInfo& method, const std::string& key) {
        if (key.rfind("sss.", 0) != 0) return true;
        const std::string_view name = std::string_view(key).substr(4);
        const auto known = renderer::sss::allSssKeys();
        if (std::find(known.begin(), known.end(), name) == known.end()) return true;
        return renderer::sss::methodUsesKey(method.method, name);
    }

    void add(const Assignment& combination, bool reference, const std::string& where) {
        Stimulus s;
        s.reference = reference;
        s.factors = combination;
        s.id = makeId(combination, reference);
        s.block = makeBlock(combination);
        s.presentation = spec_.presentation;
        for (const auto& rule : spec_.crops) {
            if (!matches(combination, rule.selection)) continue;
            if (rule.crop) {
                s.presentation.crop = rule.crop;
                s.presentation.cropWhere = rule.selection.where + ".crop";
            }
            if (rule.magnification) {
                s.presentation.magnification = *rule.magnification;
                s.presentation.magnificationWhere = rule.selection.where + ".magnification";
            }
            if (rule.method) {
                s.presentation.method = *rule.method;
                s.presentation.methodWhere = rule.selection.where + ".presentation";
            }
            break;
        }
        const renderer::sss::MethodInfo* method = methodOf(combination);
        // [fixed] holds for the whole set: an [sss] key there applies to the stimuli whose method reads it (e.g.
        // sss.samples to the screen-space methods, not to the object-space reference).
        for (const auto& p : spec_.fixed)
            if (!method || methodReads(*method, p.key)) s.overrides.push_back(p.key + "=" + p.level.overrideText);
        for (const auto& [name, level] : combination) {
            if (name == "scene") {
                s.scene = level.overrideText;
                continue;
            }
            const std::string key = sceneKeyOf(name);
            // A factor level, include or reference that sets a key its stimulus' method does not read would
            // render the same image under another name: refuse it.
            if (method && !methodReads(*method, key))
                throwInput(spec_.fileName, where,
                           key + ": " + renderer::sss::notAParameterMessage(method->method) + "; stimulus '" + s.id +
                               "' (leave such combinations out with [[exclude]])");
            s.overrides.push_back(key + "=" + level.overrideText);
        }
        if (!isIdSafe(s.id))
            throwInput(spec_.fileName, spec_.idTemplate.empty() ? where : "set.id",
                       "stimulus id '" + s.id + "' is not a valid file name (use a-z 0-9 . _ -)");
        for (const auto& other : out_) {
            if (other.id != s.id) continue;
            if (other.scene == s.scene && other.overrides == s.overrides)
                throwInput(spec_.fileName, where, "duplicates stimulus '" + s.id + "'");
            throwInput(spec_.fileName, spec_.idTemplate.empty() ? where : "set.id",
                       "two different stimuli get the id '" + s.id +
                           "' (add the missing factors to the id template or give distinct labels)");
        }
        s.index = out_.size();
        out_.push_back(std::move(s));
    }

    const SetSpec& spec_;
    std::optional<NamingTemplate> template_;
    std::vector<Stimulus> out_;
};

} // namespace

std::vector<Stimulus> expand(const SetSpec& spec) { return Expander(spec).run(); }

Shard parseShard(const std::string& text, const std::string& option) {
    size_t slash = text.find('/');
    Shard shard;
    auto number = [&](std::string_view part, int& value) {
        auto result = std::from_chars(part.data(), part.data() + part.size(), value);
        return result.ec == std::errc() && result.ptr == part.data() + part.size();
    };
    std::string_view view(text);
    if (slash == std::string::npos || !number(view.substr(0, slash), shard.index) ||
        !number(view.substr(slash + 1), shard.count))
        throwInput(option, "", "'" + text + "' is not of the form i/n (e.g. 2/8)");
    if (shard.count < 1 || shard.index < 1 || shard.index > shard.count)
        throwInput(option, "", "'" + text + "': i must be in 1.." + std::to_string(std::max(shard.count, 1)));
    return shard;
}

std::vector<Stimulus> selectShard(const std::vector<Stimulus>& all, const Shard& shard) {
    std::vector<Stimulus> out;
    for (const auto& s : all)
        if (static_cast<int>(s.index % static_cast<size_t>(shard.count)) == shard.index - 1) out.push_back(s);
    return out;
}

} // namespace skinlab::stimuli
