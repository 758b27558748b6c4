#pragma once
// The built-in scenes, builtin:halo|bleed|ear|head and the named variants builtin:halo-grey-backdrop and
// builtin:bleed-true-mask (the former defaults of halo and bleed): scene specs (TOML, renderer/scenes/builtin/NAME.toml,
// embedded into the binary) that place lights, camera and materials around the procedural models of
// builtin_geometry.h. They are read by the same strict reader as scene files, so `--set` works on them.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace skinlab::renderer {

// TOML text of builtin:NAME (NAME without the "builtin:" prefix); nullopt for an unknown name.
std::optional<std::string_view> builtinSceneText(std::string_view name);
// "halo", "bleed", "ear", "head", "halo-grey-backdrop", "bleed-true-mask".
std::vector<std::string> builtinSceneNames();

} // namespace skinlab::renderer
