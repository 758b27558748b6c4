// The stimulus manifest's entry (contract 2): one writer and one strict reader, whose errors name the file, the key
// and the value.
#include "formats/stimulus_manifest.h"

#include "common/error.h"
#include "tests/common/temp_folder.h"

#include <gtest/gtest.h>

#include <functional>

namespace skinlab::formats {
namespace {

ManifestEntry builtEntry() {
    ManifestEntry e;
    e.id = "head-mid-separable";
    e.files = {"exr/head-mid-separable.exr", "png/head-mid-separable.png"};
    e.sha256 = {std::string(64, 'a'), std::string(64, 'b')};
    e.factors = {{"method", "separable"}, {"width_mm", 2.5}};
    e.block = "builtin:head/mid";
    e.width = 320;
    e.height = 180;
    e.scene = "builtin:head";
    e.overrides = {"sss.method=\"separable\""};
    e.resolved = {{"render", {{"width", 320}}}};
    e.timingsMs = {{"stimulus_wall", 12.5}};
    e.presentation = nlohmann::json{{"magnification", 1}};
    e.predicted = Prediction{"ColorVideoVDP v0.5.6", "standard_fhd", "head-mid-reference", 9.25, "cc", "dd"};
    return e;
}

std::string errorOf(const std::function<void()>& read) {
    try {
        read();
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

nlohmann::json manifestWith(const nlohmann::json& entries) {
    return {{"format", "skinlab-stimuli"}, {"version", 1}, {"set", "demo"}, {"stimuli", entries}};
}

TEST(StimulusManifestEntry, WriterAndReaderRoundTrip) {
    const ManifestEntry entry = builtEntry();
    const nlohmann::json json = toJson(entry);
    EXPECT_EQ(json["files"]["png"], "png/head-mid-separable.png");
    EXPECT_EQ(json["predicted"]["reference_png_sha256"], "cc");
    EXPECT_FALSE(json.contains("provenance")) << "absent optional parts are not written";
    const ManifestEntry back = manifestEntryFromJson(json, "m.json", 0);
    EXPECT_EQ(toJson(back), json);
    EXPECT_EQ(back.factorText("method"), "separable");
    EXPECT_EQ(back.factorText("width_mm"), "2.5");
    EXPECT_EQ(back.factorText("view"), "");
}

TEST(StimulusManifestEntry, ErrorsNameFileKeyAndValue) {
    const nlohmann::json good = toJson(builtEntry());
    auto failure = [&](const std::function<void(nlohmann::json&)>& change) {
        nlohmann::json entry = good;
        change(entry);
        return errorOf([&] { manifestEntryFromJson(entry, "set/manifest.json", 3); });
    };
    EXPECT_EQ(failure([](nlohmann::json& e) { e.erase("id"); }), "set/manifest.json: stimuli[3].id: missing");
    EXPECT_EQ(failure([](nlohmann::json& e) { e["files"]["png"] = "../../etc/passwd"; }),
              "set/manifest.json: stimuli[3].files.png: path leaves the stimulus folder: ../../etc/passwd");
    EXPECT_EQ(failure([](nlohmann::json& e) { e["width"] = 0; }),
              "set/manifest.json: stimuli[3].width: expected an integer in [1, 16384], not 0");
    EXPECT_EQ(failure([](nlohmann::json& e) { e["reference"] = "yes"; }),
              "set/manifest.json: stimuli[3].reference: expected true or false, not \"yes\"");
    EXPECT_EQ(failure([](nlohmann::json& e) { e["predicted"]["jod"] = "high"; }),
              "set/manifest.json: stimuli[3].predicted.jod: expected a number, not \"high\"");
    EXPECT_EQ(failure([](nlohmann::json& e) { e["overrides"] = {1}; }),
              "set/manifest.json: stimuli[3].overrides: expected a list of strings, not 1");
    EXPECT_EQ(failure([](nlohmann::json& e) { e["sha256"].erase("png"); }),
              "set/manifest.json: stimuli[3].sha256.png: missing");
    // A hand-made set of renders without presented images is read; its entries have no PNG.
    const ManifestEntry renders = manifestEntryFromJson(
        {{"id", "a"}, {"files", {{"exr", "exr/a.exr"}}}, {"sha256", {{"exr", "aa"}}}, {"block", "b"}}, "m.json", 0);
    EXPECT_EQ(renders.files.png, "");
    // ... and one of presented images alone (a study shows only those).
    const ManifestEntry presented = manifestEntryFromJson({{"id", "a"},
                                                           {"files", {{"png", "png/a.png"}}},
                                                           {"sha256", {{"png", "bb"}}},
                                                           {"block", "b"},
                                                           {"width", 8},
                                                           {"height", 8}},
                                                          "m.json", 0);
    EXPECT_EQ(presented.files.exr, "");
    EXPECT_EQ(failure([](nlohmann::json& e) { e["files"] = nlohmann::json::object(); }),
              "set/manifest.json: stimuli[3].files: expected an exr or a png path");
}

// A custom display is recorded with every parameter and reads back equal (a prediction stays current); a bad
// recorded value names the file, the key and the value.
TEST(StimulusManifestEntry, CustomDisplayRoundTripsAndIsCheckedStrictly) {
    ManifestEntry entry = builtEntry();
    entry.predicted->display = "custom";
    entry.predicted->displayModel = DisplayModel{
        "custom display based on 24-inch FHD", "sRGB", 500.0, 2000.0, 0.0, 0.005, 20.0, 1920, 1080, 24.0, 0.1 + 0.2};
    const nlohmann::json json = toJson(entry);
    EXPECT_EQ(json["predicted"]["display_model"]["resolution"], nlohmann::json({1920, 1080}));
    const ManifestEntry back = manifestEntryFromJson(nlohmann::json::parse(json.dump()), "m.json", 0);
    EXPECT_EQ(back.predicted, entry.predicted) << "every double reads back exactly";
    // Without a geometry only the ppd is written.
    entry.predicted->displayModel->resolutionWidth = entry.predicted->displayModel->resolutionHeight = 0;
    entry.predicted->displayModel->diagonalInches = entry.predicted->displayModel->viewingDistanceMetres = 0.0;
    EXPECT_FALSE(toJson(entry)["predicted"]["display_model"].contains("resolution"));
    EXPECT_EQ(manifestEntryFromJson(toJson(entry), "m.json", 0).predicted, entry.predicted);

    const nlohmann::json good = json;
    auto failure = [&](const std::function<void(nlohmann::json&)>& change) {
        nlohmann::json changed = good;
        change(changed["predicted"]);
        return errorOf([&] { manifestEntryFromJson(changed, "set/manifest.json", 2); });
    };
    EXPECT_EQ(failure([](nlohmann::json& p) { p["display_model"]["contrast"] = 0.5; }),
              "set/manifest.json: stimuli[2].predicted.display_model.contrast: expected a number >= 1, not 0.5");
    EXPECT_EQ(failure([](nlohmann::json& p) { p["display_model"]["pixels_per_degree"] = -3; }),
              "set/manifest.json: stimuli[2].predicted.display_model.pixels_per_degree: expected a positive "
              "number, not -3");
    EXPECT_EQ(failure([](nlohmann::json& p) { p["display_model"]["reflectivity"] = 2; }),
              "set/manifest.json: stimuli[2].predicted.display_model.reflectivity: expected a number in [0, 1], "
              "not 2");
    EXPECT_EQ(failure([](nlohmann::json& p) { p["display_model"].erase("peak_luminance"); }),
              "set/manifest.json: stimuli[2].predicted.display_model.peak_luminance: missing");
    EXPECT_EQ(failure([](nlohmann::json& p) { p["display_model"]["resolution"] = {1920}; }),
              "set/manifest.json: stimuli[2].predicted.display_model.resolution: expected [WIDTH, HEIGHT] in pixels, "
              "not [1920]");
    EXPECT_EQ(failure([](nlohmann::json& p) { p["display"] = "standard_fhd"; }),
              "set/manifest.json: stimuli[2].predicted.display: \"standard_fhd\" with a display_model: expected "
              "\"custom\"");
    EXPECT_EQ(failure([](nlohmann::json& p) { p.erase("display_model"); }),
              "set/manifest.json: stimuli[2].predicted.display_model: missing: a custom display lists its parameters");
}

// An entry of a hand-made set that lists one kind of file is written back with that kind only.
TEST(StimulusManifestEntry, EntryWithOneKindOfFileRoundTrips) {
    const nlohmann::json renders = {
        {"id", "a"}, {"files", {{"exr", "exr/a.exr"}}}, {"sha256", {{"exr", "aa"}}}, {"block", "b"}};
    const nlohmann::json written = toJson(manifestEntryFromJson(renders, "m.json", 0));
    EXPECT_EQ(written["files"], renders["files"]);
    EXPECT_EQ(written["sha256"], renders["sha256"]);
    EXPECT_EQ(toJson(manifestEntryFromJson(written, "m.json", 0)), written);
}

TEST(StimulusManifestFile, ReadsTheFolderStrictly) {
    test_support::TempFolder folder;
    const std::string file = (folder.path() / "manifest.json").string();
    EXPECT_EQ(errorOf([&] { readStimulusManifest(folder.path()); }),
              file + ": no manifest.json in the stimulus folder");
    const nlohmann::json twice = nlohmann::json::array({toJson(builtEntry()), toJson(builtEntry())});
    folder.write("manifest.json", manifestWith(twice).dump());
    EXPECT_EQ(errorOf([&] { readStimulusManifest(folder.path()); }),
              file + ": stimuli[1].id: duplicate stimulus id \"head-mid-separable\"");
    nlohmann::json other = manifestWith(nlohmann::json::array({toJson(builtEntry())}));
    other["version"] = 2;
    folder.write("manifest.json", other.dump());
    EXPECT_EQ(errorOf([&] { readStimulusManifest(folder.path()); }),
              file + ": version: expected 1 (the only manifest version this build reads)");
    folder.write("manifest.json", manifestWith(nlohmann::json::array({toJson(builtEntry())})).dump(2));
    const StimulusManifest manifest = readStimulusManifest(folder.path());
    EXPECT_EQ(manifest.set, "demo");
    ASSERT_EQ(manifest.stimuli.size(), 1u);
    ASSERT_NE(manifest.find("head-mid-separable"), nullptr);
    EXPECT_EQ(manifest.find("head-mid-separable")->predicted->jod, 9.25);
    EXPECT_EQ(manifest.folder, std::filesystem::absolute(folder.path()));
}

} // namespace
} // namespace skinlab::formats
