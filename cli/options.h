#pragma once
// Option groups shared by the subcommands: one name, one meaning and one help text wherever an option appears,
// bound to the libraries' option structs (defaults come from the struct, shown by --help).
#include "analysis/metrics/cvvdp.h"

#include <CLI/CLI.hpp>

#include <optional>
#include <string>
#include <vector>

namespace skinlab::cli {

// --assets DIR: the folder of the shared assets that `assets:` paths name (default $SKINLAB_ASSETS).
CLI::Option* addAssetsOption(CLI::App& command, std::string& assets);

// --set KEY=VALUE (repeatable): overrides a key of the file the command reads (`what`: "spec value", "design key").
CLI::Option* addOverridesOption(CLI::App& command, std::vector<std::string>& overrides, const std::string& what);

// The viewing geometry of display-referred metrics (FLIP, ColorVideoVDP): a named display model, changed by
// --display-* (a custom display) and --ppd. `overrides` is the metrics library's own struct.
struct DisplayArguments {
    std::optional<std::string> name;                   // --display
    skinlab::metrics::CvvdpDisplayOverrides overrides; // --display-ppd, --display-diagonal-in, ...
    std::optional<std::string> resolution;             // --display-resolution WIDTHxHEIGHT
    std::optional<double> pixelsPerDegree;             // --ppd (the same as --display-ppd)

    // True when --ppd or any --display-* changes the display model.
    bool changed() const;
    // The display: --display, else `fallback` (e.g. the display of a set's predictions), else standard_fhd, with
    // the changes applied. InputError naming the option for a bad value or an unknown display name.
    skinlab::metrics::CvvdpDisplay resolve(const std::optional<std::string>& fallback = std::nullopt) const;
    // The changes alone (the --ppd and --display-* values checked), for a caller that picks the model itself.
    skinlab::metrics::CvvdpDisplayOverrides changes() const;
};

// --display NAME (help: `nameHelp`, followed by the list of models), --ppd and the --display-* options.
void addDisplayOptions(CLI::App& command, DisplayArguments& display, const std::string& nameHelp);

} // namespace skinlab::cli
