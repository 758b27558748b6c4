#include "common/spec.h"

#include "common/error.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <sstream>
#include <vector>

namespace skinlab {

namespace {
const toml::table emptyTable;

std::string formatNumber(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}

std::string parseErrorMessage(const toml::parse_error& e, std::string_view source) {
    std::ostringstream ss;
    ss << source << ':' << e.source().begin.line << ':' << e.source().begin.column << ": " << e.description();
    return ss.str();
}

std::vector<std::string> splitKey(std::string_view key) {
    std::vector<std::string> parts;
    size_t start = 0;
    while (true) {
        size_t dot = key.find('.', start);
        parts.emplace_back(key.substr(start, dot == std::string_view::npos ? std::string_view::npos : dot - start));
        if (dot == std::string_view::npos) break;
        start = dot + 1;
    }
    return parts;
}
} // namespace

struct SpecReader::State {
    std::string file;
    std::set<std::string> read;   // key paths read as values or tables
    std::set<std::string> opaque; // key paths read raw: nothing below them is checked
    std::set<std::string> asked;  // key paths looked up, present or not (the keys an unknown key may misspell)
};

toml::table parseTomlFile(const std::filesystem::path& path) {
    if (!std::filesystem::exists(path)) throwInput(path.string(), "", "file not found");
    try {
        return toml::parse_file(path.string());
    } catch (const toml::parse_error& e) {
        throw InputError(parseErrorMessage(e, path.string()));
    }
}

toml::table parseTomlString(std::string_view text, std::string_view sourceName) {
    try {
        return toml::parse(text, sourceName);
    } catch (const toml::parse_error& e) {
        throw InputError(parseErrorMessage(e, sourceName));
    }
}

void applyOverride(toml::table& root, std::string_view assignment, std::string_view source) {
    size_t eq = assignment.find('=');
    std::string quoted = "'" + std::string(assignment) + "'";
    if (eq == std::string_view::npos || eq == 0) throwInput(source, quoted, "expected key=value");
    std::string_view key = assignment.substr(0, eq);
    std::string_view text = assignment.substr(eq + 1);
    std::vector<std::string> parts = splitKey(key);
    for (const auto& p : parts)
        if (p.empty()) throwInput(source, quoted, "empty key component");

    // Parse the value as TOML; a bare word is a string.
    std::unique_ptr<toml::node> value;
    try {
        toml::table t = toml::parse("v = " + std::string(text));
        if (auto* n = t.get("v")) {
            n->visit([&](auto& concrete) { value = std::make_unique<std::decay_t<decltype(concrete)>>(concrete); });
        }
    } catch (const toml::parse_error&) {
    }
    if (!value) value = std::make_unique<toml::value<std::string>>(std::string(text));

    // A component may index an existing array: "lights[0]". Returns the name and the index (npos: none).
    auto splitIndex = [&](const std::string& part) -> std::pair<std::string, size_t> {
        const size_t bracket = part.find('[');
        if (bracket == std::string::npos) return {part, std::string::npos};
        if (bracket == 0) throwInput(source, quoted, "empty key component");
        if (part.back() != ']') throwInput(source, quoted, "expected NAME[INDEX] in '" + part + "'");
        const std::string digits = part.substr(bracket + 1, part.size() - bracket - 2);
        if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos || digits.size() > 6)
            throwInput(source, quoted, "index '" + digits + "' is not a non-negative integer");
        return {part.substr(0, bracket), std::stoul(digits)};
    };
    std::string path;
    // The array `name` of `table`, checked to hold element `index`.
    auto indexedArray = [&](toml::table& table, const std::string& name, size_t index) -> toml::array& {
        path += (path.empty() ? "" : ".") + name;
        toml::node* child = table.get(name);
        if (!child || !child->is_array())
            throwInput(source, path, "is not an array, cannot index it in '" + std::string(key) + "'");
        toml::array& array = *child->as_array();
        if (index >= array.size())
            throwInput(source, path,
                       "has " + std::to_string(array.size()) + " element(s); index " + std::to_string(index) +
                           " is out of range");
        path += "[" + std::to_string(index) + "]";
        return array;
    };

    toml::table* table = &root;
    for (size_t i = 0; i + 1 < parts.size(); ++i) {
        const auto [name, index] = splitIndex(parts[i]);
        toml::node* child = nullptr;
        if (index == std::string::npos) {
            path += (path.empty() ? "" : ".") + name;
            child = table->get(name);
            if (!child) {
                table->insert(name, toml::table{});
                child = table->get(name);
            }
        } else {
            child = indexedArray(*table, name, index).get(index);
        }
        if (!child->is_table()) throwInput(source, path, "is not a table, cannot set '" + std::string(key) + "'");
        table = child->as_table();
    }
    const auto [leaf, index] = splitIndex(parts.back());
    if (index == std::string::npos) {
        value->visit([&](auto& concrete) { table->insert_or_assign(leaf, concrete); });
        return;
    }
    // "name[i]=value": replace one element of an existing array.
    toml::array& array = indexedArray(*table, leaf, index);
    value->visit([&](auto& concrete) { array.replace(array.cbegin() + static_cast<std::ptrdiff_t>(index), concrete); });
}

nlohmann::json tomlToJson(const toml::node& node) {
    if (auto* t = node.as_table()) {
        nlohmann::json out = nlohmann::json::object();
        for (auto&& [k, v] : *t) out[std::string(k.str())] = tomlToJson(v);
        return out;
    }
    if (auto* a = node.as_array()) {
        nlohmann::json out = nlohmann::json::array();
        for (auto&& v : *a) out.push_back(tomlToJson(v));
        return out;
    }
    if (auto* s = node.as_string()) return s->get();
    if (auto* i = node.as_integer()) return i->get();
    if (auto* f = node.as_floating_point()) return f->get();
    if (auto* b = node.as_boolean()) return b->get();
    std::string out;
    node.visit([&](auto&& v) {
        std::ostringstream ss;
        ss << v;
        out = ss.str();
    });
    return out;
}

std::string describeNode(const toml::node& node) {
    if (auto* s = node.as_string()) return "string \"" + s->get() + "\"";
    if (auto* i = node.as_integer()) return "integer " + std::to_string(i->get());
    if (auto* f = node.as_floating_point()) return "float " + formatNumber(f->get());
    if (auto* b = node.as_boolean()) return std::string("boolean ") + (b->get() ? "true" : "false");
    if (node.is_table()) return "table";
    if (node.is_array()) return "array";
    return "date/time";
}

SpecReader::SpecReader(const toml::table& table, std::string file, std::string prefix)
    : table_(&table), prefix_(std::move(prefix)), state_(std::make_shared<State>()) {
    state_->file = std::move(file);
}

SpecReader::SpecReader(const toml::table* table, std::string prefix, std::shared_ptr<State> state)
    : table_(table), prefix_(std::move(prefix)), state_(std::move(state)) {}

const std::string& SpecReader::file() const { return state_->file; }

std::string SpecReader::keyPath(std::string_view key) const {
    return prefix_.empty() ? std::string(key) : prefix_ + "." + std::string(key);
}

bool SpecReader::has(std::string_view key) const { return get(key) != nullptr; }

const toml::node* SpecReader::get(std::string_view key) const {
    state_->asked.insert(keyPath(key));
    return table_->get(key);
}

void SpecReader::mark(std::string_view key, bool opaque) const {
    state_->read.insert(keyPath(key));
    if (opaque) state_->opaque.insert(keyPath(key));
}

void SpecReader::markRead(std::string_view key) const { mark(key, true); }

void SpecReader::fail(std::string_view key, std::string_view message) const {
    throwInput(state_->file, keyPath(key), message);
}

double SpecReader::number(std::string_view key, double fallback, double min, double max) const {
    const toml::node* n = get(key);
    if (!n) return fallback;
    mark(key, false);
    double v;
    if (auto* i = n->as_integer()) v = static_cast<double>(i->get());
    else if (auto* f = n->as_floating_point()) v = f->get();
    else fail(key, "expected a number, got " + describeNode(*n));
    if (!std::isfinite(v) || v < min || v > max)
        fail(key, formatNumber(v) + " is out of range [" + formatNumber(min) + ", " + formatNumber(max) + "]");
    return v;
}

double SpecReader::requiredNumber(std::string_view key, double min, double max) const {
    if (!has(key)) fail(key, "missing (a number in [" + formatNumber(min) + ", " + formatNumber(max) + "])");
    return number(key, 0.0, min, max);
}

std::int64_t SpecReader::integer(std::string_view key, std::int64_t fallback, std::int64_t min,
                                 std::int64_t max) const {
    const toml::node* n = get(key);
    if (!n) return fallback;
    mark(key, false);
    auto* i = n->as_integer();
    if (!i) fail(key, "expected an integer, got " + describeNode(*n));
    std::int64_t v = i->get();
    if (v < min || v > max)
        fail(key, std::to_string(v) + " is out of range [" + std::to_string(min) + ", " + std::to_string(max) + "]");
    return v;
}

bool SpecReader::boolean(std::string_view key, bool fallback) const {
    const toml::node* n = get(key);
    if (!n) return fallback;
    mark(key, false);
    auto* b = n->as_boolean();
    if (!b) fail(key, "expected true or false, got " + describeNode(*n));
    return b->get();
}

std::string SpecReader::string(std::string_view key, const std::string& fallback) const {
    const toml::node* n = get(key);
    if (!n) return fallback;
    mark(key, false);
    auto* s = n->as_string();
    if (!s) fail(key, "expected a string, got " + describeNode(*n));
    return s->get();
}

std::string SpecReader::requiredString(std::string_view key) const {
    if (!has(key)) fail(key, "missing (a string)");
    return string(key, "");
}

std::string SpecReader::choice(std::string_view key, const std::string& fallback,
                               const std::vector<std::string>& allowed) const {
    std::string v = string(key, fallback);
    for (const auto& a : allowed)
        if (a == v) return v;
    std::string list;
    for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
    fail(key, "'" + v + "' is not one of: " + list);
}

std::vector<double> SpecReader::numbers(std::string_view key, std::vector<double> fallback, double min,
                                        double max) const {
    const toml::node* n = get(key);
    if (!n) return fallback;
    mark(key, false);
    auto* a = n->as_array();
    if (!a) fail(key, "expected an array of numbers, got " + describeNode(*n));
    std::vector<double> out;
    for (size_t i = 0; i < a->size(); ++i) {
        const toml::node& e = *a->get(i);
        double v;
        if (auto* iv = e.as_integer()) v = static_cast<double>(iv->get());
        else if (auto* f = e.as_floating_point()) v = f->get();
        else fail(key, "element " + std::to_string(i) + ": expected a number, got " + describeNode(e));
        if (!std::isfinite(v) || v < min || v > max)
            fail(key, "element " + std::to_string(i) + ": " + formatNumber(v) + " is out of range [" +
                          formatNumber(min) + ", " + formatNumber(max) + "]");
        out.push_back(v);
    }
    return out;
}

std::array<double, 3> SpecReader::vec3(std::string_view key, std::array<double, 3> fallback, double min,
                                       double max) const {
    if (!has(key)) return fallback;
    std::vector<double> v = numbers(key, {}, min, max);
    if (v.size() != 3) fail(key, "expected 3 numbers, got " + std::to_string(v.size()));
    return {v[0], v[1], v[2]};
}

std::vector<std::string> SpecReader::strings(std::string_view key, std::vector<std::string> fallback) const {
    const toml::node* n = get(key);
    if (!n) return fallback;
    mark(key, false);
    auto* a = n->as_array();
    if (!a) fail(key, "expected an array of strings, got " + describeNode(*n));
    std::vector<std::string> out;
    for (size_t i = 0; i < a->size(); ++i) {
        auto* s = a->get(i)->as_string();
        if (!s) fail(key, "element " + std::to_string(i) + ": expected a string, got " + describeNode(*a->get(i)));
        out.push_back(s->get());
    }
    return out;
}

SpecReader SpecReader::table(std::string_view key) const {
    const toml::node* n = get(key);
    if (!n) return SpecReader(&emptyTable, keyPath(key), state_);
    mark(key, false);
    if (!n->is_table()) fail(key, "expected a table, got " + describeNode(*n));
    return SpecReader(n->as_table(), keyPath(key), state_);
}

std::vector<SpecReader> SpecReader::tables(std::string_view key) const {
    const toml::node* n = get(key);
    std::vector<SpecReader> out;
    if (!n) return out;
    mark(key, false);
    auto* a = n->as_array();
    if (!a) fail(key, "expected an array of tables, got " + describeNode(*n));
    for (size_t i = 0; i < a->size(); ++i) {
        auto* t = a->get(i)->as_table();
        if (!t) fail(key, "element " + std::to_string(i) + ": expected a table, got " + describeNode(*a->get(i)));
        out.push_back(SpecReader(t, keyPath(key) + "[" + std::to_string(i) + "]", state_));
    }
    return out;
}

const toml::node* SpecReader::raw(std::string_view key) const {
    const toml::node* n = get(key);
    if (n) mark(key, true);
    return n;
}

namespace {
// Optimal string alignment distance: insertions, deletions, substitutions and swaps of neighbours ("fov_dge").
std::size_t editDistance(std::string_view a, std::string_view b) {
    std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
    for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
    for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i)
        for (std::size_t j = 1; j <= b.size(); ++j) {
            d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
                d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
        }
    return d[a.size()][b.size()];
}
} // namespace

std::string nearestKey(std::string_view unknown, const std::vector<std::string>& known) {
    std::string best;
    std::size_t bestDistance = 0;
    for (const std::string& candidate : known) {
        const std::size_t distance = editDistance(unknown, candidate);
        // Close enough to be a slip of the keyboard: at most 2 edits and a third of the key (1 below 6 letters).
        const std::size_t allowed = std::min<std::size_t>(2, std::max<std::size_t>(1, candidate.size() / 3));
        if (distance == 0 || distance > allowed || distance >= candidate.size()) continue;
        if (best.empty() || distance < bestDistance || (distance == bestDistance && candidate < best)) {
            best = candidate;
            bestDistance = distance;
        }
    }
    return best;
}

void SpecReader::checkUnread(const toml::table& table, const std::string& prefix) const {
    for (auto&& [k, v] : table) {
        std::string path = prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
        if (!state_->read.count(path)) {
            // The keys this table was asked for and does not have: "fov_dge" is likely "fov_deg".
            std::vector<std::string> known;
            const std::string parent = prefix.empty() ? "" : prefix + ".";
            for (const std::string& asked : state_->asked) {
                if (asked.size() <= parent.size() || asked.compare(0, parent.size(), parent) != 0) continue;
                const std::string name = asked.substr(parent.size());
                if (name.find_first_of(".[") == std::string::npos && !table.contains(name)) known.push_back(name);
            }
            const std::string hint = nearestKey(k.str(), known);
            throwInput(state_->file, path, hint.empty() ? "unknown key" : "unknown key (did you mean " + hint + "?)");
        }
        if (state_->opaque.count(path)) continue;
        if (auto* t = v.as_table()) checkUnread(*t, path);
        if (auto* a = v.as_array()) {
            for (size_t i = 0; i < a->size(); ++i)
                if (auto* et = a->get(i)->as_table()) checkUnread(*et, path + "[" + std::to_string(i) + "]");
        }
    }
}

void SpecReader::finish() const { checkUnread(*table_, prefix_); }

} // namespace skinlab
