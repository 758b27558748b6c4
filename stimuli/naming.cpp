#include "stimuli/naming.h"

#include <charconv>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <stdexcept>

namespace skinlab::stimuli {

namespace {
bool isIdChar(char c) { return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '.' || c == '_' || c == '-'; }
} // namespace

bool isIdSafe(std::string_view text) {
    if (text.empty() || text.front() == '.' || text.front() == '-') return false;
    for (char c : text)
        if (!isIdChar(c)) return false;
    return true;
}

std::string sanitizeLabel(std::string_view text) {
    std::string out;
    for (char c : text) {
        char lower = (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c;
        if (isIdChar(lower)) {
            out += lower;
        } else if (!out.empty() && out.back() != '-') {
            out += '-';
        }
    }
    while (!out.empty() && (out.back() == '-')) out.pop_back();
    while (!out.empty() && (out.front() == '-' || out.front() == '.')) out.erase(out.begin());
    return out;
}

std::string sceneLabel(std::string_view scene) {
    constexpr std::string_view builtinPrefix = "builtin:";
    if (scene.substr(0, builtinPrefix.size()) == builtinPrefix)
        return sanitizeLabel(scene.substr(builtinPrefix.size()));
    return sanitizeLabel(std::filesystem::path(std::string(scene)).stem().string());
}

std::string lastKeyComponent(std::string_view key) {
    size_t dot = key.rfind('.');
    return std::string(dot == std::string_view::npos ? key : key.substr(dot + 1));
}

std::string tomlValueText(const toml::node& node) {
    if (auto* s = node.as_string()) return nlohmann::json(s->get()).dump(); // JSON escapes are valid TOML
    if (auto* i = node.as_integer()) return std::to_string(i->get());
    if (auto* b = node.as_boolean()) return b->get() ? "true" : "false";
    if (auto* f = node.as_floating_point()) {
        double v = f->get();
        if (!std::isfinite(v)) throw std::invalid_argument("a non-finite number is not allowed");
        // Shortest text that reads back to the same double; TOML needs a '.' or exponent for a float.
        char buffer[64];
        auto result = std::to_chars(buffer, buffer + sizeof buffer, v);
        std::string text(buffer, result.ptr);
        if (text.find_first_of(".eE") == std::string::npos) text += ".0";
        return text;
    }
    if (auto* a = node.as_array()) {
        std::string text = "[";
        for (size_t i = 0; i < a->size(); ++i) text += (i ? ", " : "") + tomlValueText(*a->get(i));
        return text + "]";
    }
    if (node.is_table()) throw std::invalid_argument("a table is not allowed here");
    throw std::invalid_argument("a date or time is not allowed here");
}

NamingTemplate parseNamingTemplate(std::string_view text) {
    NamingTemplate result;
    std::string literal;
    for (size_t i = 0; i < text.size(); ++i) {
        char c = text[i];
        if (c == '{') {
            size_t close = text.find('}', i + 1);
            if (close == std::string_view::npos) throw std::invalid_argument("'{' without a closing '}'");
            std::string name(text.substr(i + 1, close - i - 1));
            if (name.empty()) throw std::invalid_argument("empty placeholder {}");
            if (!literal.empty()) result.parts.push_back({false, literal});
            literal.clear();
            result.parts.push_back({true, name});
            i = close;
        } else if (c == '}') {
            throw std::invalid_argument("'}' without an opening '{'");
        } else if (!isIdChar(c)) {
            throw std::invalid_argument(std::string("character '") + c + "' is not allowed in ids (use a-z 0-9 . _ -)");
        } else {
            literal += c;
        }
    }
    if (!literal.empty()) result.parts.push_back({false, literal});
    return result;
}

} // namespace skinlab::stimuli
