#include "renderer/pathtraced/json_table.h"

#include "common/error.h"

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

namespace skinlab::renderer::pathtraced {

toml::table jsonAsTomlTable(const nlohmann::json& json, std::string_view source, std::string_view table) {
    const std::string name(table);
    if (!json.is_object()) throwInput(source, name, "expected a JSON object, got " + json.dump());
    toml::table values;
    for (const auto& [key, value] : json.items()) {
        if (value.is_boolean()) values.insert_or_assign(key, value.get<bool>());
        else if (value.is_number_integer()) values.insert_or_assign(key, value.get<std::int64_t>());
        else if (value.is_number()) values.insert_or_assign(key, value.get<double>());
        else if (value.is_string()) values.insert_or_assign(key, value.get<std::string>());
        else if (value.is_array()) {
            toml::array array;
            for (const auto& element : value) array.push_back(element.get<double>());
            values.insert_or_assign(key, std::move(array));
        } else throwInput(source, name + "." + key, "unsupported value " + value.dump());
    }
    toml::table root;
    root.insert_or_assign(name, std::move(values));
    return root;
}

} // namespace skinlab::renderer::pathtraced
