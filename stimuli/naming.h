#pragma once
// Names of things in a stimulus set: level labels, stimulus ids from a naming template, TOML value text.
#include <string>
#include <string_view>
#include <toml++/toml.h>
#include <vector>

namespace skinlab::stimuli {

// True for a non-empty string of [a-z0-9._-] not starting with '.' or '-' (safe as a file name on every OS).
bool isIdSafe(std::string_view text);

// Lower-cases and replaces every character outside [a-z0-9._-] by '-', collapsing runs and trimming '-'.
std::string sanitizeLabel(std::string_view text);

// The label of a scene: "builtin:head" → "head", "../scenes/lee-perry-smith.toml" → "lee-perry-smith".
std::string sceneLabel(std::string_view scene);

// The last component of a dotted key: "sss.follow_surface" → "follow_surface".
std::string lastKeyComponent(std::string_view key);

// TOML text of a scalar or array value, exactly parseable back by applyOverride ("\"a\"", "20", "0.5", "[1, 2]").
// Throws std::invalid_argument for tables, dates and non-finite numbers.
std::string tomlValueText(const toml::node& node);

// A parsed naming template: literal text and {factor} placeholders.
struct NamingTemplate {
    struct Part {
        bool placeholder = false;
        std::string text; // literal text, or the factor name of a placeholder
    };
    std::vector<Part> parts;
};

// Parses "{scene}-{view}-{method}". Throws std::invalid_argument with a reason on unbalanced braces, empty
// placeholders or literal characters that are not id-safe.
NamingTemplate parseNamingTemplate(std::string_view text);

} // namespace skinlab::stimuli
