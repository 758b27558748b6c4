#pragma once
// The JSON form of a scene table back to TOML: a resolved record's [sss], [transmittance], [pathtraced] and [eevee]
// (as their toJson() writes them) go through the same strict SpecReader as a scene file.
#include <nlohmann/json_fwd.hpp>
#include <string_view>
#include <toml++/toml.h>

namespace skinlab {

// {`table`: {...}} from a JSON object. Nested objects become tables, arrays keep their elements' types. InputError
// "SOURCE: TABLE: expected a JSON object, got ..." or "SOURCE: TABLE.KEY: unsupported value ..." (null) otherwise.
toml::table jsonAsTomlTable(const nlohmann::json& json, std::string_view source, std::string_view table);

} // namespace skinlab
