// Unit tests of stimulus-set specs: parsing, factorial expansion, exclusions, includes, references, naming,
// shards, the manifest's JSON/CSV, and every spec-level bad-input message word for word. No GL.
#include "common/error.h"
#include "stimuli/build.h"
#include "stimuli/contact_sheet.h"
#include "stimuli/expansion.h"
#include "stimuli/manifest.h"
#include "stimuli/naming.h"
#include "stimuli/output_folder.h"
#include "stimuli/presentation.h"
#include "stimuli/set_spec.h"
#include "tests/common/temp_folder.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <gtest/gtest.h>

namespace fs = std::filesystem;
using namespace skinlab::stimuli;

namespace {

const fs::path kSpecFile = "set.toml"; // a name for messages; relative scene paths resolve next to it

SetSpec spec(const std::string& text, const std::vector<std::string>& overrides = {}) {
    return readSetSpecString(text, kSpecFile, overrides);
}

std::vector<std::string> ids(const std::vector<Stimulus>& stimuli) {
    std::vector<std::string> out;
    for (const auto& s : stimuli) out.push_back(s.id);
    return out;
}

// The message of the InputError thrown by f, or "" when nothing is thrown.
template <class F>
std::string errorOf(F&& f) {
    try {
        f();
    } catch (const skinlab::InputError& e) {
        return e.what();
    }
    return "";
}

const std::string kBase = R"(
[set]
name = "demo"
scene = "builtin:head"

[fixed]
render = { width = 96, height = 64 }

[[factor]]
name = "view"
levels = ["close", "mid"]

[[factor]]
name = "method"
levels = ["none", "separable", "gaussian-sum"]
)";

} // namespace

TEST(StimulusExpansion, FullFactorialInOrderWithDefaultNames) {
    std::vector<Stimulus> all = expand(spec(kBase));
    EXPECT_EQ(ids(all), (std::vector<std::string>{"head-close-none", "head-close-separable", "head-close-gaussian-sum",
                                                  "head-mid-none", "head-mid-separable", "head-mid-gaussian-sum"}));
    const Stimulus& s = all[4];
    EXPECT_EQ(s.block, "builtin:head/mid");
    EXPECT_EQ(s.scene, "builtin:head");
    EXPECT_FALSE(s.reference);
    EXPECT_EQ(s.index, 4u);
    EXPECT_EQ(s.overrides, (std::vector<std::string>{"render.height=64", "render.width=96", "camera.view=\"mid\"",
                                                     "sss.method=\"separable\""}));
}

TEST(StimulusExpansion, ExclusionsRemoveMatchingCombinations) {
    std::vector<Stimulus> all = expand(spec(kBase + R"(
[[exclude]]
view = "close"
method = ["separable", "gaussian-sum"]
)"));
    EXPECT_EQ(ids(all), (std::vector<std::string>{"head-close-none", "head-mid-none", "head-mid-separable",
                                                  "head-mid-gaussian-sum"}));
}

TEST(StimulusExpansion, NumericAndBooleanLevelsGetReadableLabels) {
    std::vector<Stimulus> all = expand(spec(R"(
[set]
name = "sweep"
scene = "builtin:head"
[[factor]]
name = "sss.samples"
levels = [5, 25]
[[factor]]
name = "sss.follow_surface"
levels = [true, false]
[[factor]]
name = "sss.width_mm"
levels = [0.5]
)"));
    EXPECT_EQ(ids(all), (std::vector<std::string>{"head-samples-5-follow_surface-width_mm-0.5",
                                                  "head-samples-5-no-follow_surface-width_mm-0.5",
                                                  "head-samples-25-follow_surface-width_mm-0.5",
                                                  "head-samples-25-no-follow_surface-width_mm-0.5"}));
    EXPECT_EQ(all[1].overrides,
              (std::vector<std::string>{"sss.samples=5", "sss.follow_surface=false", "sss.width_mm=0.5"}));
    EXPECT_EQ(all[1].block, "builtin:head"); // no view factor and no fixed view: the block is the scene
}

TEST(StimulusExpansion, NamingTemplateAndLabels) {
    std::vector<Stimulus> all = expand(spec(R"(
[set]
name = "t"
scene = "builtin:halo"
id = "{method}_{sss.samples}"
[[factor]]
name = "method"
levels = ["separable", "artistic"]
labels = ["sep", "art"]
[[factor]]
name = "sss.samples"
levels = [9, 17]
labels = ["n9", "n17"]
)"));
    EXPECT_EQ(ids(all), (std::vector<std::string>{"sep_n9", "sep_n17", "art_n9", "art_n17"}));
}

TEST(StimulusExpansion, IncludesAndReferencesExpandOverBlockFactors) {
    std::vector<Stimulus> all = expand(spec(kBase + R"(
[[factor]]
name = "sss.samples"
levels = [11, 21]

[[exclude]]
method = "none"

[[exclude]]
method = "separable"
"sss.samples" = 21

[[include]]
method = "separable"
sss.samples = 63
view = "mid"

[[reference]]
method = "reference"
)"));
    // 2 views × (separable: 1 + gaussian-sum: 2) = 6, + 1 include, + 1 reference per view.
    ASSERT_EQ(all.size(), 9u);
    EXPECT_EQ(all[6].id, "head-mid-separable-samples-63");
    EXPECT_EQ(all[6].overrides.back(), "sss.samples=63");
    EXPECT_FALSE(all[6].reference);
    EXPECT_EQ(all[7].id, "head-close-reference");
    EXPECT_EQ(all[8].id, "head-mid-reference");
    EXPECT_TRUE(all[8].reference);
    EXPECT_EQ(all[8].block, "builtin:head/mid");
    // A reference leaves non-block factors (samples) at the scene's default.
    EXPECT_EQ(all[8].overrides, (std::vector<std::string>{"render.height=64", "render.width=96", "camera.view=\"mid\"",
                                                          "sss.method=\"reference\""}));
}

// An [sss] key the stimulus' method does not read is refused in a factor, an include and a reference alike, naming
// the key, the method and the stimulus; a key in [fixed] applies to the stimuli whose method reads it.
TEST(StimulusExpansion, KeysOfAnotherMethodAreRefused) {
    const std::string base = R"(
[set]
name = "demo"
scene = "builtin:head"
[[factor]]
name = "method"
levels = ["separable", "artistic"]
)";
    EXPECT_EQ(errorOf([&] {
                  expand(spec(base + "[[include]]\nmethod = \"artistic\"\nsss.profile = \"burley\"\n"));
              }).rfind("set.toml: include[0]: sss.profile: not a parameter of method 'artistic' (its keys: ", 0),
              0u);
    EXPECT_NE(errorOf([&] {
                  expand(spec(base + "[[factor]]\nname = \"sss.pscbf_sigma\"\nlevels = [\"std-dev\"]\n"));
              }).find("sss.pscbf_sigma: not a parameter of method 'separable'"),
              std::string::npos);
    EXPECT_NE(errorOf([&] {
                  expand(spec(base + "[[reference]]\nmethod = \"reference\"\nsss.samples = 11\n"));
              }).find("sss.samples: not a parameter of method 'reference'"),
              std::string::npos);
    // The same key where it belongs: fine.
    EXPECT_EQ(errorOf([&] { expand(spec(base + "[[include]]\nmethod = \"separable\"\nsss.profile = \"burley\"\n")); }),
              "");
    // [fixed]: sss.samples and sss.sampling go where they are read; width_mm (read by every method) everywhere.
    const std::vector<Stimulus> all = expand(spec(base + R"(
[fixed]
sss = { samples = 11, sampling = "importance", width_mm = 2.0 }
[[reference]]
method = "reference"
)"));
    ASSERT_EQ(all.size(), 3u);
    EXPECT_EQ(all[0].overrides, (std::vector<std::string>{"sss.samples=11", "sss.sampling=\"importance\"",
                                                          "sss.width_mm=2.0", "sss.method=\"separable\""}));
    EXPECT_EQ(all[1].overrides,
              (std::vector<std::string>{"sss.samples=11", "sss.width_mm=2.0", "sss.method=\"artistic\""}));
    EXPECT_EQ(all[2].overrides, (std::vector<std::string>{"sss.width_mm=2.0", "sss.method=\"reference\""}));
}

TEST(StimulusExpansion, SceneFactorAndFixedView) {
    std::vector<Stimulus> all = expand(spec(R"(
[set]
name = "scenes"
[fixed]
camera.view = "far"
[[factor]]
name = "scene"
levels = ["builtin:halo", "builtin:bleed"]
[[factor]]
name = "method"
levels = ["none"]
)"));
    EXPECT_EQ(ids(all), (std::vector<std::string>{"halo-none", "bleed-none"}));
    EXPECT_EQ(all[1].block, "builtin:bleed/far");
    EXPECT_EQ(all[1].scene, "builtin:bleed");
}

TEST(StimulusExpansion, OverridesOfTheSpecApply) {
    std::vector<Stimulus> all = expand(spec(kBase, {"fixed.render.width=128", "set.name=other"}));
    EXPECT_EQ(all[0].overrides[1], "render.width=128");
    EXPECT_NE(spec(kBase).sha256, spec(kBase, {"fixed.render.width=128"}).sha256);
    EXPECT_EQ(spec(kBase).sha256, spec(kBase).sha256);
}

TEST(StimulusExpansion, ShardsPartitionTheSetRoundRobin) {
    std::vector<Stimulus> all = expand(spec(kBase));
    std::vector<std::string> seen;
    for (int i = 1; i <= 4; ++i)
        for (const auto& s : selectShard(all, Shard{i, 4})) {
            EXPECT_EQ(s.index % 4, static_cast<size_t>(i - 1));
            seen.push_back(s.id);
        }
    std::sort(seen.begin(), seen.end());
    std::vector<std::string> expected = ids(all);
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(seen, expected);
    EXPECT_EQ(parseShard("3/8").index, 3);
    EXPECT_EQ(parseShard("3/8").count, 8);
    EXPECT_EQ(errorOf([] { parseShard("0/4"); }), "--shard: '0/4': i must be in 1..4");
    EXPECT_EQ(errorOf([] { parseShard("5/4"); }), "--shard: '5/4': i must be in 1..4");
    EXPECT_EQ(errorOf([] { parseShard("two"); }), "--shard: 'two' is not of the form i/n (e.g. 2/8)");
}

TEST(StimulusNaming, LabelsAndValues) {
    EXPECT_EQ(sceneLabel("builtin:head"), "head");
    EXPECT_EQ(sceneLabel("../../renderer/scenes/lee-perry-smith.toml"), "lee-perry-smith");
    EXPECT_EQ(sanitizeLabel("Gaussian Sum/2"), "gaussian-sum-2");
    EXPECT_TRUE(isIdSafe("head-mid-separable"));
    EXPECT_FALSE(isIdSafe("../x"));
    EXPECT_FALSE(isIdSafe("Head"));
    toml::table t = toml::parse("a = 0.1\nb = \"x\\\"y\"\nc = [1, 2.5]\nd = 3.0");
    EXPECT_EQ(tomlValueText(*t.get("a")), "0.1");
    EXPECT_EQ(tomlValueText(*t.get("b")), "\"x\\\"y\"");
    EXPECT_EQ(tomlValueText(*t.get("c")), "[1, 2.5]");
    EXPECT_EQ(tomlValueText(*t.get("d")), "3.0");
}

// Every spec-level bad input, word for word (scene-level ones are in test_stimuli_build.cpp: they need the
// renderer's resolveScene()).
struct BadSpec {
    const char* name;
    std::string text;
    std::string message;
};

class StimulusSpecErrors : public ::testing::TestWithParam<BadSpec> {};

TEST_P(StimulusSpecErrors, OneLineNamingFileAndKey) {
    const BadSpec& c = GetParam();
    EXPECT_EQ(errorOf([&] { expand(spec(c.text)); }), c.message);
}

INSTANTIATE_TEST_SUITE_P(
    AllCases, StimulusSpecErrors,
    ::testing::Values(
        BadSpec{"EmptyFactorial", kBase + "[[exclude]]\nview = [\"close\", \"mid\"]\n",
                "set.toml: exclude: the factorial is empty (every combination is excluded)"},
        BadSpec{"FactorWithoutLevels", kBase + "[[factor]]\nname = \"sss.samples\"\nlevels = []\n",
                "set.toml: factor[2].levels: factor 'sss.samples' has no levels"},
        BadSpec{"ConflictWithFixed", kBase + "[[factor]]\nname = \"render.width\"\nlevels = [64, 128]\n",
                "set.toml: factor[2].name: 'render.width' conflicts with the fixed parameter fixed.render.width "
                "(held the same for every stimulus of the set)"},
        BadSpec{"ExposureNeverVaries", kBase + "[[factor]]\nname = \"render.exposure_ev\"\nlevels = [0, 1]\n",
                "set.toml: factor[2].name: 'render.exposure_ev' is held fixed across every stimulus set (set "
                "render.exposure_ev in [fixed]); it cannot vary"},
        BadSpec{"ToneMapperNeverVaries", kBase + "[[factor]]\nname = \"tone_map.operator\"\nlevels = [\"linear\"]\n",
                "set.toml: factor[2].name: 'tone_map.operator' is held fixed across every stimulus set (set tone_map "
                "in [fixed]); it cannot vary"},
        BadSpec{"IncludeConflictsWithFixed", kBase + "[[include]]\nrender.width = 32\n",
                "set.toml: include[0].render.width: 'render.width' conflicts with the fixed parameter "
                "fixed.render.width (held the same for every stimulus of the set)"},
        BadSpec{"UnknownLevelInExclude", kBase + "[[exclude]]\nmethod = \"separabel\"\n",
                "set.toml: exclude[0].method: 'separabel' is not a level of factor 'method'"},
        BadSpec{"ExcludeOfUnknownFactor", kBase + "[[exclude]]\nsss.samples = 3\n",
                "set.toml: exclude[0].sss.samples: 'sss.samples' is not a factor of this set"},
        BadSpec{"DuplicateLevel", kBase + "[[factor]]\nname = \"sss.samples\"\nlevels = [5, 5]\n",
                "set.toml: factor[2].levels[1]: '5' is listed twice"},
        BadSpec{"SameKeyTwice", kBase + "[[factor]]\nname = \"sss.method\"\nlevels = [\"none\"]\n",
                "set.toml: factor[2].name: 'sss.method' varies the same scene key as factor 'method'"},
        BadSpec{"UnknownSpecKey", kBase + "[set2]\nx = 1\n", "set.toml: set2: unknown key"},
        BadSpec{"UnknownFactorField", kBase + "[[factor]]\nname = \"sss.samples\"\nlevels = [5]\nlevel = 3\n",
                "set.toml: factor[2].level: unknown key"},
        BadSpec{"MissingScene", "[set]\nname = \"x\"\n[[factor]]\nname = \"method\"\nlevels = [\"none\"]\n",
                "set.toml: set.scene: missing (a scene \"builtin:NAME\" or scene spec path, or a [[factor]] named "
                "scene)"},
        BadSpec{"MissingSceneFile", "[set]\nname = \"x\"\nscene = \"no-such-scene.toml\"\n",
                "set.toml: set.scene: scene file 'no-such-scene.toml' not found"},
        BadSpec{"BadSetName", "[set]\nname = \"My Set\"\nscene = \"builtin:head\"\n",
                "set.toml: set.name: 'My Set' is not a valid set name (use a-z 0-9 . _ -)"},
        BadSpec{"UnknownSetKey", kBase + "[set.x]\n", "set.toml: set.x: unknown key"},
        BadSpec{"IdCollision",
                "[set]\nname = \"x\"\nscene = \"builtin:head\"\nid = \"{scene}\"\n[[factor]]\nname = \"method\"\n"
                "levels = [\"none\", \"separable\"]\n",
                "set.toml: set.id: two different stimuli get the id 'head' (add the missing factors to the id "
                "template or give distinct labels)"},
        BadSpec{"TemplateUnknownPlaceholder",
                "[set]\nname = \"x\"\nscene = \"builtin:head\"\nid = \"{scene}-{metod}\"\n",
                "set.toml: set.id: placeholder {metod} is not a factor of this set"},
        BadSpec{"DuplicateInclude", kBase + "[[include]]\nview = \"mid\"\nmethod = \"none\"\n",
                "set.toml: include[0]: duplicates stimulus 'head-mid-none'"},
        BadSpec{"LabelCountMismatch", kBase + "[[factor]]\nname = \"sss.samples\"\nlevels = [5, 9]\nlabels = [\"a\"]\n",
                "set.toml: factor[2].labels: 1 labels for 2 levels"},
        BadSpec{"SceneTwice", kBase + "[[factor]]\nname = \"scene\"\nlevels = [\"builtin:halo\"]\n",
                "set.toml: factor[2].name: the scene is both fixed (set.scene) and a factor; keep one"},
        BadSpec{"TableLevel", kBase + "[[factor]]\nname = \"sss.samples\"\nlevels = [{a = 1}]\n",
                "set.toml: factor[2].levels[0]: a table is not allowed here"}),
    [](const ::testing::TestParamInfo<BadSpec>& param) { return std::string(param.param.name); });

TEST(StimulusManifest, JsonRoundTripAndCsv) {
    SetSpec s = spec(kBase);
    std::vector<Stimulus> all = expand(s);
    Manifest m = manifestHeader(s, all, Shard{2, 3});
    m.renderer = {"llvmpipe", "4.5", "0.1.0"};
    skinlab::formats::ManifestEntry entry;
    entry.id = "head-mid-none";
    entry.files = {"exr/head-mid-none.exr", "png/head-mid-none.png"};
    entry.sha256 = {"aa", "bb"};
    entry.factors = {{"scene", "builtin:head"}, {"view", "mid"}, {"method", "none"}};
    entry.block = "builtin:head/mid";
    entry.width = 96;
    entry.height = 64;
    entry.timingsMs = {{"stimulus_wall", 12.5}};
    m.stimuli.push_back(entry);
    nlohmann::json j = toJson(m);
    EXPECT_EQ(j["format"], "skinlab-stimuli");
    EXPECT_EQ(j["version"], 1);
    EXPECT_EQ(j["set"], "demo");
    EXPECT_EQ(j["spec_sha256"], s.sha256);
    EXPECT_EQ(j["renderer"]["gl_renderer"], "llvmpipe");
    EXPECT_EQ(j["set_ids"].size(), 6u);
    Manifest back = manifestFromJson(j, "m.json");
    EXPECT_EQ(toJson(back), j);
    EXPECT_EQ(manifestCsv(m),
              "id,block,reference,scene,view,method,exr,png,sha256_exr,sha256_png,width,height,wall_ms\n"
              "head-mid-none,builtin:head/mid,0,builtin:head,mid,none,exr/head-mid-none.exr,png/head-mid-none.png,"
              "aa,bb,96,64,12.5\n");
    EXPECT_EQ(errorOf([] {
                  manifestFromJson({{"format", "x"}}, "m.json");
              }),
              "m.json: format: expected \"skinlab-stimuli\"");
}

// contact.png's captions name a scene file by its factor label, a reference's own scene by its short name, and say
// that the JOD is predicted (the reference has none: 10 by definition).
TEST(ContactSheet, CaptionsUseLabelsAndSayPredicted) {
    const std::string scene = "../../renderer/scenes/evaluation/bleed-coarse-mask.toml";
    Manifest m;
    m.set = "demo";
    m.factors = nlohmann::json::array(
        {{{"name", "scene"}, {"key", "scene"}, {"levels", {{{"value", scene}, {"label", "bleed"}}}}},
         {{"name", "method"},
          {"key", "sss.method"},
          {"levels", {{{"value", "none"}, {"label", "none"}}, {{"value", "separable"}, {"label", "separable"}}}}},
         {{"name", "sss.cbf"},
          {"key", "sss.cbf"},
          {"levels", {{{"value", "true"}, {"label", "cbf"}}, {{"value", "false"}, {"label", "no-cbf"}}}}}});
    auto entry = [&](const std::string& id, nlohmann::json factors, bool reference, double jod) {
        skinlab::formats::ManifestEntry e;
        e.id = id;
        e.block = "patches";
        e.factors = std::move(factors);
        e.reference = reference;
        if (!reference) {
            e.predicted = skinlab::formats::Prediction{};
            e.predicted->jod = jod;
        }
        return e;
    };
    m.stimuli = {entry("a", {{"scene", scene}, {"method", "separable"}, {"sss.cbf", "true"}}, false, 8.1666),
                 entry("b", {{"scene", scene}, {"method", "none"}, {"sss.cbf", "false"}}, false, 9.5),
                 entry("r", {{"scene", "builtin:bleed-true-mask"}, {"method", "reference"}}, true, 10.0)};
    EXPECT_EQ(contactSheetCaptions(m), (std::vector<std::string>{"bleed separable cbf=true - predicted 8.17 JOD",
                                                                 "bleed none cbf=false - predicted 9.50 JOD",
                                                                 "bleed-true-mask reference (ref)"}));
}

TEST(StimulusOutputFolder, RefusesForeignFolders) {
    const skinlab::test_support::TempFolder temp;
    const fs::path& dir = temp.path();
    EXPECT_FALSE(claimOutputFolder(dir, "demo", std::nullopt).has_value()); // empty: fine
    std::ofstream(dir / "notes.txt") << "mine";
    EXPECT_EQ(errorOf([&] { claimOutputFolder(dir, "demo", std::nullopt); }),
              dir.string() +
                  ": is not empty and holds no stimulus set (no manifest.json); choose a new or empty folder");
    fs::remove(dir / "notes.txt");
    SetSpec s = spec(kBase);
    writeManifest(dir, manifestHeader(s, expand(s), std::nullopt));
    EXPECT_TRUE(claimOutputFolder(dir, "demo", std::nullopt).has_value());
    EXPECT_EQ(errorOf([&] { claimOutputFolder(dir, "other", std::nullopt); }),
              dir.string() + ": holds stimulus set 'demo', not 'other'; choose another folder");
    EXPECT_EQ(errorOf([&] {
                  claimOutputFolder(dir, "demo", Shard{1, 2});
              }),
              dir.string() + ": holds the whole set of set 'demo', not shard 1/2; choose another folder");
    EXPECT_TRUE(fs::exists(dir / "manifest.json")); // nothing stored is lost
}

namespace {
// The shipped specs that render the scanned head (the others use built-in scenes only).
bool needsHead(const std::string& file) {
    return file.rfind("thesis-", 0) == 0 || file == "extensions-head.toml" || file == "demo-scan.toml" ||
           file == "eevee-methods-scan.toml";
}

// The spec to read without the scanned head, and its overrides: set.scene=builtin:head where the head is the set's
// scene; where it is a level of the scene factor (demo-scan.toml), a copy of the spec in a temporary folder with
// that level builtin:head and the other scene files' paths absolute (in `folder`, which outlives the spec's use).
fs::path withoutHead(const fs::path& spec, std::vector<std::string>& overrides, const fs::path& folder) {
    std::ifstream in(spec);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string head = "\"../../renderer/scenes/lee-perry-smith.toml\"";
    const size_t at = text.find("levels = [" + head);
    if (at == std::string::npos) {
        overrides.push_back("set.scene=builtin:head");
        return spec;
    }
    text.replace(at + 10, head.size(), "\"builtin:head\"");
    const std::string relative = "\"../../renderer/";
    const std::string absolute = "\"" + (fs::path(SKINLAB_SOURCE_DIR) / "renderer").string() + "/";
    for (size_t p = text.find(relative); p != std::string::npos; p = text.find(relative, p + absolute.size()))
        text.replace(p, relative.size(), absolute);
    std::ofstream(folder / spec.filename()) << text;
    return folder / spec.filename();
}
} // namespace

// The shipped specs parse and expand to the documented counts (docs/stimuli.md). The thesis specs' scene is
// swapped for builtin:head with a --set override so this runs without the scanned head.
TEST(ShippedSpecs, ExpandToTheDocumentedCounts) {
    const skinlab::test_support::TempFolder headless;
    const fs::path dir = fs::path(SKINLAB_SOURCE_DIR) / "stimuli" / "specs";
    const std::vector<std::pair<std::string, size_t>> expected = {{"demo.toml", 26},
                                                                  {"demo-scan.toml", 26},
                                                                  {"thesis-fig5.2-methods.toml", 18},
                                                                  {"thesis-fig3.16-halos.toml", 7},
                                                                  {"thesis-fig3.17-bleeding.toml", 7},
                                                                  {"thesis-fig3.19-curvature.toml", 6},
                                                                  {"thesis-fig5.3-materials.toml", 7},
                                                                  {"thesis-fig5.1-samples.toml", 34},
                                                                  {"extensions-halo.toml", 50},
                                                                  {"extensions-bleed.toml", 25},
                                                                  {"extensions-head.toml", 25},
                                                                  {"extensions-ear.toml", 16},
                                                                  {"extensions-flat.toml", 10},
                                                                  {"eevee-methods.toml", 9},
                                                                  {"eevee-methods-scan.toml", 9},
                                                                  {"skin-tones.toml", 18}};
    size_t specs = 0;
    for (const auto& entry : fs::directory_iterator(dir))
        if (entry.path().extension() == ".toml") ++specs;
    EXPECT_EQ(specs, expected.size()) << "a spec was added or removed: update this test and docs/stimuli.md";
    for (const auto& [file, count] : expected) {
        std::vector<std::string> overrides;
        const fs::path path = needsHead(file) ? withoutHead(dir / file, overrides, headless.path()) : dir / file;
        SetSpec s = readSetSpec(path, overrides);
        std::vector<Stimulus> all = expand(s);
        EXPECT_EQ(all.size(), count) << file;
        for (const auto& st : all) {
            EXPECT_TRUE(isIdSafe(st.id)) << st.id;
            EXPECT_FALSE(st.block.empty()) << st.id;
        }
        // Every thesis figure has its fixed resolution, exposure and tone mapper.
        std::vector<std::string> fixedKeys;
        for (const auto& p : s.fixed) fixedKeys.push_back(p.key);
        for (const char* key : {"render.width", "render.height", "render.exposure_ev", "tone_map.operator"})
            EXPECT_NE(std::find(fixedKeys.begin(), fixedKeys.end(), key), fixedKeys.end()) << file << " " << key;
    }
    std::vector<Stimulus> demo = expand(readSetSpec(dir / "demo.toml"));
    EXPECT_EQ(demo.front().id, "head-face-none");
    EXPECT_EQ(demo.back().id, "bleed-true-mask-edge-patches-reference"); // the references come last
    // Three blocks (the face, the silhouette and the patches), each with one reference and its own presentation.
    std::map<std::string, int> references;
    for (const Stimulus& st : demo) references[st.block] += st.reference ? 1 : 0;
    EXPECT_EQ(references, (std::map<std::string, int>{{"close", 1}, {"explicit", 1}, {"mid", 1}}));
}

// The demo's study designs study every block their stimulus set builds (scripts/demo.sh renders them all), and each
// condition is a stimulus id of the set.
TEST(ShippedSpecs, DemoDesignsStudyEveryBlockTheSetBuilds) {
    const skinlab::test_support::TempFolder headless;
    const fs::path specs = fs::path(SKINLAB_SOURCE_DIR) / "stimuli" / "specs";
    const fs::path designs = fs::path(SKINLAB_SOURCE_DIR) / "experiments" / "designs";
    for (const std::string file : {"demo.toml", "demo-scan.toml"}) {
        std::vector<std::string> overrides;
        const fs::path path = needsHead(file) ? withoutHead(specs / file, overrides, headless.path()) : specs / file;
        const std::vector<Stimulus> all = expand(readSetSpec(path, overrides));
        std::set<std::string> blocks, ids;
        for (const Stimulus& st : all) {
            blocks.insert(st.block);
            ids.insert(st.id);
        }
        const toml::table design = toml::parse_file((designs / file).string());
        std::set<std::string> studied;
        for (const auto& b : *design["blocks"].as_array()) studied.insert(b.value<std::string>().value_or(""));
        EXPECT_EQ(studied, blocks) << file;
        for (const auto& c : *design["conditions"].as_array()) {
            const std::string id = c.value<std::string>().value_or("");
            EXPECT_TRUE(ids.count(id)) << file << ": " << id;
        }
    }
}

namespace {
// Plans every shipped spec (no rendering): with $SKINLAB_ASSETS set the thesis specs use the scanned head as
// shipped, otherwise builtin:head stands in for it. One (file name, plan) per spec.
void planShippedSpecs(std::vector<std::pair<std::string, BuildPlan>>& plans, const fs::path& headless) {
    const fs::path dir = fs::path(SKINLAB_SOURCE_DIR) / "stimuli" / "specs";
    const char* assets = std::getenv("SKINLAB_ASSETS");
    const bool haveHead = assets && *assets && fs::exists(fs::path(assets) / "LeePerrySmith");
    if (!haveHead) std::printf("  $SKINLAB_ASSETS unset: the thesis specs are checked on builtin:head\n");
    for (const auto& entry : fs::directory_iterator(dir)) {
        if (entry.path().extension() != ".toml") continue;
        const std::string file = entry.path().filename().string();
        std::vector<std::string> overrides;
        const fs::path path =
            !haveHead && needsHead(file) ? withoutHead(entry.path(), overrides, headless) : entry.path();
        BuildPlan plan;
        ASSERT_NO_THROW(plan = planBuild(path, overrides, std::nullopt, haveHead ? fs::path(assets) : fs::path()))
            << file;
        plans.emplace_back(file, std::move(plan));
    }
}
} // namespace

// Every stimulus of every shipped spec resolves against the renderer's scene reader (methods, extension switches
// and their levels exist; no GL). With $SKINLAB_ASSETS set the thesis specs use the scanned head as shipped;
// otherwise builtin:head stands in for it.
TEST(ShippedSpecs, EveryStimulusResolves) {
    const skinlab::test_support::TempFolder headless;
    std::vector<std::pair<std::string, BuildPlan>> plans;
    ASSERT_NO_FATAL_FAILURE(planShippedSpecs(plans, headless.path()));
    size_t resolved = 0;
    for (const auto& [file, plan] : plans) {
        EXPECT_EQ(plan.resolved.size(), plan.all.size()) << file;
        resolved += plan.resolved.size();
    }
    EXPECT_GT(resolved, 80u);
}

// No presented PNG of a shipped spec is a nearest-neighbour upsample: every crop or magnification resolves to a
// native presentation, a render.window of the magnified frame (the renderer draws it; nothing renders here).
TEST(ShippedSpecs, EveryMagnifiedCropRendersNatively) {
    const skinlab::test_support::TempFolder headless;
    std::vector<std::pair<std::string, BuildPlan>> plans;
    ASSERT_NO_FATAL_FAILURE(planShippedSpecs(plans, headless.path()));
    size_t magnified = 0;
    for (const auto& [file, plan] : plans) {
        for (size_t i = 0; i < plan.selected.size(); ++i) {
            const Stimulus& s = plan.selected[i];
            const std::string where = file + ": " + s.id;
            const nlohmann::json entryJson = plannedEntryJson(s, plan.resolved[i]);
            EXPECT_EQ(entryJson["presentation"]["method"], "native") << where;
            if (!presents(s.presentation)) continue;
            ++magnified;
            const int m = s.presentation.magnification;
            const CropRect c = effectiveCrop(s.presentation, entryJson["presentation"]["render"]["width"],
                                             entryJson["presentation"]["render"]["height"]);
            EXPECT_EQ(
                plan.resolved[i]["render"]["window"],
                (nlohmann::json{{"x", c.x * m}, {"y", c.y * m}, {"width", c.width * m}, {"height", c.height * m}}))
                << where;
        }
    }
    EXPECT_GT(magnified, 40u);
}

// Presentation: [fixed] crop and magnification, [[crop]] per block (first match), every bad value refused naming
// its key. Whether a crop lies inside the frame needs the render size (tests/stimuli/test_stimuli_build.cpp).
TEST(StimulusPresentation, FixedAndPerBlockCropsAndMagnification) {
    const std::string text = kBase + R"(
[[crop]]
view = "mid"
crop = { x = 30, y = 10, width = 32, height = 40 }
magnification = 2
)";
    std::string withFixed = text;
    withFixed.replace(withFixed.find("render = { width = 96, height = 64 }"), 36,
                      "render = { width = 96, height = 64 }\ncrop = { x = 20, y = 8, width = 40, height = 30 }\n"
                      "magnification = 3");
    const SetSpec s = spec(withFixed);
    ASSERT_TRUE(s.presentation.crop.has_value());
    EXPECT_EQ(*s.presentation.crop, (CropRect{20, 8, 40, 30}));
    EXPECT_EQ(s.presentation.magnification, 3);
    // crop and magnification are not scene keys: no override carries them.
    for (const auto& p : s.fixed) EXPECT_EQ(p.key.rfind("render.", 0), 0u) << p.key;
    const std::vector<Stimulus> all = expand(s);
    ASSERT_EQ(all.size(), 6u);
    EXPECT_EQ(all[0].presentation.crop, (CropRect{20, 8, 40, 30}));
    EXPECT_EQ(all[0].presentation.magnification, 3);
    EXPECT_EQ(all[0].presentation.cropWhere, "fixed.crop");
    EXPECT_EQ(all[4].presentation.crop, (CropRect{30, 10, 32, 40}));
    EXPECT_EQ(all[4].presentation.magnification, 2);
    EXPECT_EQ(all[4].presentation.cropWhere, "crop[0].crop");
    EXPECT_EQ(all[4].presentation.magnificationWhere, "crop[0].magnification");
    for (const auto& o : all[4].overrides) EXPECT_EQ(o.find("crop"), std::string::npos) << o;
    // Without any: the whole frame at magnification 1.
    const std::vector<Stimulus> plain = expand(spec(kBase));
    EXPECT_FALSE(plain[0].presentation.crop.has_value());
    EXPECT_EQ(plain[0].presentation.magnification, 1);
    // A reference is presented like its block.
    const std::vector<Stimulus> refs = expand(spec(text + "[[reference]]\nmethod = \"reference\"\n"));
    EXPECT_EQ(refs.back().id, "head-mid-reference");
    EXPECT_EQ(refs.back().presentation.crop, (CropRect{30, 10, 32, 40}));
}

TEST(StimulusPresentation, BadCropsAndMagnificationsAreRefusedNamingTheKey) {
    auto fixedError = [](const std::string& lines) {
        std::string text = kBase;
        text.replace(text.find("render = { width = 96, height = 64 }"), 36,
                     "render = { width = 96, height = 64 }\n" + lines);
        return errorOf([&] { spec(text); });
    };
    EXPECT_EQ(fixedError("crop = { x = 0, y = 0, width = 0, height = 10 }"),
              "set.toml: fixed.crop.width: 0 is out of range [1, 16384]");
    EXPECT_EQ(fixedError("crop = { x = 0, y = 0, width = 10, height = 0 }"),
              "set.toml: fixed.crop.height: 0 is out of range [1, 16384]");
    EXPECT_EQ(fixedError("crop = { x = -1, y = 0, width = 10, height = 10 }"),
              "set.toml: fixed.crop.x: -1 is out of range [0, 16384]");
    EXPECT_EQ(fixedError("crop = { x = 0, y = 0, width = 10 }"),
              "set.toml: fixed.crop.height: missing (a crop has x, y, width, height in pixels)");
    EXPECT_EQ(fixedError("crop = { x = 0, y = 0, width = 10, height = 10, w = 3 }"),
              "set.toml: fixed.crop.w: unknown key (a crop has x, y, width, height)");
    EXPECT_EQ(fixedError("crop = { x = 0, y = 0, width = 10.5, height = 10 }"),
              "set.toml: fixed.crop.width: expected an integer, got float 10.5");
    EXPECT_EQ(fixedError("crop = [0, 0, 10, 10]"),
              "set.toml: fixed.crop: expected a table { x, y, width, height }, got array");
    EXPECT_EQ(fixedError("magnification = 0"), "set.toml: fixed.magnification: 0 is out of range [1, 16]");
    EXPECT_EQ(fixedError("magnification = 17"), "set.toml: fixed.magnification: 17 is out of range [1, 16]");
    EXPECT_EQ(fixedError("magnification = 1.5"), "set.toml: fixed.magnification: expected an integer, got float 1.5");
    // [[crop]]: only block factors select, with levels of them; something to apply.
    EXPECT_EQ(
        errorOf([&] { spec(kBase + "[[crop]]\nmethod = \"none\"\ncrop = { x = 0, y = 0, width = 8, height = 8 }\n"); }),
        "set.toml: crop[0].method: 'method' is not a block factor of this set (a crop applies to whole blocks, "
        "so that every condition of a block is presented alike)");
    EXPECT_EQ(
        errorOf([&] { spec(kBase + "[[crop]]\nview = \"far\"\ncrop = { x = 0, y = 0, width = 8, height = 8 }\n"); }),
        "set.toml: crop[0].view: 'far' is not a level of factor 'view'");
    EXPECT_EQ(errorOf([&] { spec(kBase + "[[crop]]\nview = \"mid\"\n"); }),
              "set.toml: crop[0]: gives none of crop = { x, y, width, height }, magnification, presentation");
    EXPECT_EQ(errorOf([&] { spec(kBase + "[[crop]]\nview = \"mid\"\nmagnification = 99\n"); }),
              "set.toml: crop[0].magnification: 99 is out of range [1, 16]");
}
