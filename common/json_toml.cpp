#include "common/json_toml.h"

#include "common/error.h"

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

namespace skinlab {

namespace {

toml::table jsonObjectAsToml(const nlohmann::json& object, std::string_view source, const std::string& path);

void insertJson(toml::table& table, const std::string& key, const nlohmann::json& value, std::string_view source,
                const std::string& path) {
    const std::string where = path + "." + key;
    if (value.is_boolean()) table.insert_or_assign(key, value.get<bool>());
    else if (value.is_number_integer()) table.insert_or_assign(key, value.get<std::int64_t>());
    else if (value.is_number()) table.insert_or_assign(key, value.get<double>());
    else if (value.is_string()) table.insert_or_assign(key, value.get<std::string>());
    else if (value.is_object()) table.insert_or_assign(key, jsonObjectAsToml(value, source, where));
    else if (value.is_array()) {
        toml::array array;
        for (const auto& element : value) {
            if (element.is_number_integer()) array.push_back(element.get<std::int64_t>());
            else if (element.is_number()) array.push_back(element.get<double>());
            else if (element.is_string()) array.push_back(element.get<std::string>());
            else if (element.is_boolean()) array.push_back(element.get<bool>());
            else throwInput(source, where, "unsupported array element " + element.dump());
        }
        table.insert_or_assign(key, std::move(array));
    } else throwInput(source, where, "unsupported value " + value.dump());
}

toml::table jsonObjectAsToml(const nlohmann::json& object, std::string_view source, const std::string& path) {
    if (!object.is_object()) throwInput(source, path, "expected a JSON object, got " + object.dump());
    toml::table table;
    for (const auto& [key, value] : object.items()) insertJson(table, key, value, source, path);
    return table;
}

} // namespace

toml::table jsonAsTomlTable(const nlohmann::json& json, std::string_view source, std::string_view table) {
    toml::table root;
    root.insert_or_assign(std::string(table), jsonObjectAsToml(json, source, std::string(table)));
    return root;
}

} // namespace skinlab
