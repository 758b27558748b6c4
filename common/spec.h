#pragma once
// Strict specs (scene specs, stimulus-set specs, study designs) in TOML.
//
// A SpecReader reads values with defaults and ranges and remembers every key it read; finish() then reports the
// first key that was never read as "FILE: KEY: unknown key" (pbrt-v4 / Mitsuba policy: an unused parameter is an
// error, never silently ignored). All errors are skinlab::InputError with one line naming the file and key:
//   scene.toml: camera.fov_deg: 200 is out of range [1, 179]
//   scene.toml: camera.fov_deg: expected a number, got string "wide"
//   scene.toml: camera.fvo: unknown key
//   scene.toml: camera.fov_dge: unknown key (did you mean fov_deg?)   (a key the reader asked for, a slip away)
#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <toml++/toml.h>
#include <vector>

namespace skinlab {

// Parses a TOML file; errors read "FILE:LINE:COLUMN: message" (InputError).
toml::table parseTomlFile(const std::filesystem::path& path);
// Parses TOML text; `sourceName` stands for the file in error messages.
toml::table parseTomlString(std::string_view text, std::string_view sourceName);

// Applies one "a.b.c=value" override (the --set syntax). The value is read as a TOML value (number, boolean,
// "quoted string", [array], {inline table}); anything else is taken as a bare string (so --set camera.view=close
// works). Intermediate tables are created. A component may index an existing array: lights[0].intensity=2
// sets one light's intensity, render.size[1]=720 one element of an array value; an index must exist (arrays are
// not extended this way; set the whole array for that). `source` names the origin in errors (e.g. "--set").
void applyOverride(toml::table& root, std::string_view assignment, std::string_view source = "--set");

// TOML → JSON (for "resolved parameters" records). Dates/times become strings.
nlohmann::json tomlToJson(const toml::node& node);

class SpecReader {
public:
    SpecReader(const toml::table& table, std::string file, std::string prefix = "");

    bool has(std::string_view key) const;
    // Full dotted key path of `key` under this reader ("camera.fov_deg"), as used in messages.
    std::string keyPath(std::string_view key) const;
    const std::string& file() const;

    double number(std::string_view key, double fallback, double min, double max) const;
    double requiredNumber(std::string_view key, double min, double max) const;
    std::int64_t integer(std::string_view key, std::int64_t fallback, std::int64_t min, std::int64_t max) const;
    bool boolean(std::string_view key, bool fallback) const;
    std::string string(std::string_view key, const std::string& fallback) const;
    std::string requiredString(std::string_view key) const;
    std::string choice(std::string_view key, const std::string& fallback,
                       const std::vector<std::string>& allowed) const;
    std::array<double, 3> vec3(std::string_view key, std::array<double, 3> fallback, double min, double max) const;
    std::vector<double> numbers(std::string_view key, std::vector<double> fallback, double min, double max) const;
    std::vector<std::string> strings(std::string_view key, std::vector<std::string> fallback) const;

    // Sub-table (an empty one if absent). Its keys are checked by finish() of this reader or of the sub-reader.
    SpecReader table(std::string_view key) const;
    // Array of tables ([[lights]]); each element reader has prefix "key[i]".
    std::vector<SpecReader> tables(std::string_view key) const;
    // Raw node (nullptr if absent); marks the key and everything below it as read.
    const toml::node* raw(std::string_view key) const;
    // Marks a key as read without reading it (e.g. keys handled elsewhere).
    void markRead(std::string_view key) const;

    [[noreturn]] void fail(std::string_view key, std::string_view message) const;
    // Throws InputError for the first key below this reader that was never read.
    void finish() const;

private:
    struct State;
    SpecReader(const toml::table* table, std::string prefix, std::shared_ptr<State> state);
    const toml::node* get(std::string_view key) const;
    void mark(std::string_view key, bool opaque) const;
    void checkUnread(const toml::table& table, const std::string& prefix) const;

    const toml::table* table_;
    std::string prefix_;
    std::shared_ptr<State> state_;
};

// The entry of `known` a slip of the keyboard away from `unknown` (at most 2 edits — insert, delete, replace, swap
// neighbours — and a third of its length, 1 below 6 letters), the closest; empty when none is.
std::string nearestKey(std::string_view unknown, const std::vector<std::string>& known);

// Describes a TOML node's type and value for messages: `string "wide"`, `integer 3`, `table`.
std::string describeNode(const toml::node& node);

} // namespace skinlab
