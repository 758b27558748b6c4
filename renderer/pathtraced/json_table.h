#pragma once
// The JSON form of a Blender method's table (`[pathtraced]`, `[eevee]`, as their toJson writes it) back to TOML, so
// that it goes through the same strict reader as a scene file.
#include <string_view>

#include <nlohmann/json_fwd.hpp>
#include <toml++/toml.h>

namespace skinlab::renderer::pathtraced {

// {"table": {...}} for SpecReader; InputError "SOURCE: TABLE: expected a JSON object" or
// "SOURCE: TABLE.KEY: unsupported value" for anything toJson never writes.
toml::table jsonAsTomlTable(const nlohmann::json& json, std::string_view source, std::string_view table);

} // namespace skinlab::renderer::pathtraced
