// `skinlab stimuli import` through the real CLI: tables (CSV and TOML) of tiny images written here with
// OpenImageIO (8-bit and 16-bit PNG, JPEG, float EXR) become set folders whose manifest, hashes and pixels are
// checked; every refusal is one exact line with exit code 2 and nothing written; and an imported set goes through
// `study create` → `study serve` → `study simulate` → `study export` → `analyze scale` → `report --no-pdf`, the
// report computing its image metrics against the imported block references.
#include "child_process.h"
#include "common/files.h"
#include "common/hash.h"
#include "stimuli/import.h"
#include "stimulus_set_fixture.h"

#include <OpenImageIO/imageio.h>
#include <cmath>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <regex>

namespace fs = std::filesystem;
using skinlab::experiments::test_support::ChildProcess;
using skinlab::experiments::test_support::CommandResult;
using skinlab::experiments::test_support::runCommand;
using skinlab::experiments::test_support::TempFolder;
using skinlab::experiments::test_support::writeText;

namespace {

CommandResult runSkinlab(std::vector<std::string> arguments) {
    arguments.insert(arguments.begin(), SKINLAB_CLI);
    return runCommand(arguments);
}

// A pattern distinct per `seed`, values in [0, 1] (every 8-bit code appears somewhere across seeds).
std::vector<float> pattern(int width, int height, int seed, float scale = 1.0f) {
    std::vector<float> rgb(static_cast<size_t>(width * height * 3));
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            for (int c = 0; c < 3; ++c)
                rgb[static_cast<size_t>((y * width + x) * 3 + c)] =
                    scale * static_cast<float>((x * 37 + y * 11 + c * 53 + seed * 29) % 256) / 255.0f;
    return rgb;
}

void writeImage(const fs::path& path, int width, int height, OIIO::TypeDesc type, const std::vector<float>& rgb,
                int channels = 3) {
    fs::create_directories(path.parent_path());
    auto out = OIIO::ImageOutput::create(path.string());
    ASSERT_TRUE(out) << OIIO::geterror();
    OIIO::ImageSpec spec(width, height, channels, type);
    spec.attribute("oiio:UnassociatedAlpha", 1); // the file stores the colour as given, not divided by alpha
    std::vector<float> data = rgb;
    if (channels == 4) { // RGB + an alpha of 0.5, which the import must ignore (never multiplied in)
        data.clear();
        for (size_t i = 0; i < rgb.size(); i += 3) data.insert(data.end(), {rgb[i], rgb[i + 1], rgb[i + 2], 0.5f});
    }
    ASSERT_TRUE(out->open(path.string(), spec));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, data.data()));
    ASSERT_TRUE(out->close());
}

std::vector<float> readImage(const fs::path& path, OIIO::TypeDesc type, int& width, int& height) {
    auto in = OIIO::ImageInput::open(path.string());
    EXPECT_TRUE(in) << path;
    if (!in) return {};
    width = in->spec().width;
    height = in->spec().height;
    EXPECT_EQ(in->spec().nchannels, 3) << path;
    std::vector<float> rgb(static_cast<size_t>(width * height * 3));
    EXPECT_TRUE(in->read_image(0, 0, 0, 3, type, rgb.data()));
    return rgb;
}

nlohmann::json readManifest(const fs::path& dir) {
    return nlohmann::json::parse(skinlab::readFile(dir / "manifest.json"));
}

const nlohmann::json& entry(const nlohmann::json& manifest, const std::string& id) {
    for (const auto& s : manifest.at("stimuli"))
        if (s.at("id") == id) return s;
    static const nlohmann::json none;
    ADD_FAILURE() << "no stimulus " << id;
    return none;
}

// Every listed file exists and has the manifest's sha256.
void expectHashes(const fs::path& dir, const nlohmann::json& manifest) {
    for (const auto& s : manifest.at("stimuli"))
        for (const char* kind : {"exr", "png"})
            EXPECT_EQ(skinlab::sha256File(dir / s.at("files").at(kind).get<std::string>()),
                      s.at("sha256").at(kind).get<std::string>())
                << s.at("id") << " " << kind;
}

} // namespace

TEST(StimuliImport, CsvTableOfPngJpegAndExrImages) {
    TempFolder folder("import-csv");
    const fs::path root = folder.path();
    const int w = 20, h = 12;
    writeImage(root / "img" / "Unreal Close.png", w, h, OIIO::TypeDesc::UINT8, pattern(w, h, 1), 4);
    writeImage(root / "img" / "unity.png", w, h, OIIO::TypeDesc::UINT16, pattern(w, h, 2));
    writeImage(root / "img" / "photo.jpg", w, h, OIIO::TypeDesc::UINT8, pattern(w, h, 3));
    writeImage(root / "img" / "ref.exr", w, h, OIIO::TypeDesc::FLOAT, pattern(w, h, 4, 0.4f));
    const fs::path table = writeText(root, "other-renderers.csv",
                                     "file,factor:method,factor:quality,reference,encoding,exposure_ev\n"
                                     "img/Unreal Close.png,unreal,1,,,\n"
                                     "img/unity.png,unity,2,false,srgb,\n"
                                     "img/photo.jpg,photo,3,,,\n"
                                     "img/ref.exr,reference,4,true,linear,1\n");
    const fs::path out = root / "set";
    CommandResult r = runSkinlab({"stimuli", "import", table.string(), "-o", out.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(r.out.rfind("stimuli: imported set 'other-renderers': 4 stimuli in 1 block(s); manifest: " +
                              (out / "manifest.json").string() + "\ncontact sheet: " + (out / "contact.html").string() +
                              "\nstimuli: predicted: block other-renderers: 3 "
                              "stimuli predicted ",
                          0),
              0u)
        << r.out;

    const nlohmann::json m = readManifest(out);
    EXPECT_EQ(m.at("format"), "skinlab-stimuli");
    EXPECT_EQ(m.at("version"), 1);
    EXPECT_EQ(m.at("set"), "other-renderers");
    EXPECT_EQ(m.at("spec"), "other-renderers.csv");
    EXPECT_EQ(m.at("spec_sha256"), skinlab::sha256File(table));
    EXPECT_EQ(m.at("complete"), true);
    EXPECT_EQ(m.at("renderer").at("gl_renderer"), "imported");
    EXPECT_EQ(m.at("set_ids"), nlohmann::json({"unreal-close", "unity", "photo", "ref"}));
    ASSERT_EQ(m.at("factors").size(), 2u);
    EXPECT_EQ(m.at("factors")[0].at("name"), "method");
    EXPECT_EQ(m.at("factors")[0].at("levels").size(), 4u);
    EXPECT_EQ(m.at("factors")[1].at("levels")[2].at("value"), "3");
    expectHashes(out, m);
    EXPECT_TRUE(fs::is_regular_file(out / "manifest.csv"));
    EXPECT_TRUE(fs::is_regular_file(out / "contact.png"));

    const auto& unreal = entry(m, "unreal-close");
    EXPECT_EQ(unreal.at("factors"), nlohmann::json({{"method", "unreal"}, {"quality", "1"}}));
    EXPECT_EQ(unreal.at("block"), "other-renderers");
    EXPECT_EQ(unreal.at("reference"), false);
    EXPECT_EQ(unreal.at("width"), w);
    EXPECT_EQ(unreal.at("height"), h);
    EXPECT_EQ(unreal.at("provenance").at("kind"), "imported");
    EXPECT_EQ(unreal.at("provenance").at("original"), "img/Unreal Close.png");
    EXPECT_EQ(unreal.at("provenance").at("original_sha256"), skinlab::sha256File(root / "img" / "Unreal Close.png"));
    EXPECT_EQ(unreal.at("provenance").at("encoding"), "srgb");
    EXPECT_EQ(entry(m, "photo").at("provenance").at("encoding"), "srgb");
    const auto& ref = entry(m, "ref");
    EXPECT_EQ(ref.at("reference"), true);
    EXPECT_EQ(ref.at("provenance").at("encoding"), "linear");
    EXPECT_EQ(ref.at("provenance").at("exposure_ev"), 1.0);
    // Predicted visibility against the block's reference, as in a built set.
    EXPECT_FALSE(ref.contains("predicted"));
    for (const char* id : {"unreal-close", "unity", "photo"}) {
        const auto& predicted = entry(m, id).at("predicted");
        EXPECT_EQ(predicted.at("reference"), "ref") << id;
        EXPECT_EQ(predicted.at("display"), "standard_fhd") << id;
        EXPECT_LT(predicted.at("jod").get<double>(), 10.0) << id;
    }

    // An 8-bit sRGB image keeps its codes in the PNG (alpha ignored); its EXR holds the sRGB-decoded values.
    int pw = 0, ph = 0;
    const std::vector<float> source = pattern(w, h, 1);
    const std::vector<float> png = readImage(out / "png" / "unreal-close.png", OIIO::TypeDesc::FLOAT, pw, ph);
    const std::vector<float> exr = readImage(out / "exr" / "unreal-close.exr", OIIO::TypeDesc::FLOAT, pw, ph);
    ASSERT_EQ(png.size(), source.size());
    ASSERT_EQ(exr.size(), source.size());
    for (size_t i = 0; i < source.size(); ++i) {
        ASSERT_NEAR(png[i], source[i], 1e-6) << i;
        ASSERT_NEAR(exr[i], skinlab::stimuli::srgbToLinear(source[i]), 1e-6) << i;
    }
    // A linear EXR: exposure applied in the EXR (×2 for +1 EV), a plain sRGB encode (clipped at 1) in the PNG.
    const std::vector<float> linear = pattern(w, h, 4, 0.4f);
    const std::vector<float> refExr = readImage(out / "exr" / "ref.exr", OIIO::TypeDesc::FLOAT, pw, ph);
    const std::vector<float> refPng = readImage(out / "png" / "ref.png", OIIO::TypeDesc::FLOAT, pw, ph);
    ASSERT_EQ(refExr.size(), linear.size());
    for (size_t i = 0; i < linear.size(); ++i) {
        ASSERT_FLOAT_EQ(refExr[i], 2.0f * linear[i]) << i;
        ASSERT_NEAR(refPng[i], std::round(255.0f * skinlab::stimuli::linearToSrgb(2.0f * linear[i])) / 255.0f, 1e-6)
            << i;
    }
    // 16-bit sRGB: the PNG rounds to 8 bits.
    const std::vector<float> unity = readImage(out / "png" / "unity.png", OIIO::TypeDesc::FLOAT, pw, ph);
    const std::vector<float> unitySource = pattern(w, h, 2);
    for (size_t i = 0; i < unity.size(); ++i) ASSERT_NEAR(unity[i], unitySource[i], 0.5 / 255 + 1e-6) << i;

    // Importing again gives the same files (byte for byte).
    const fs::path again = root / "again";
    ASSERT_EQ(runSkinlab({"stimuli", "import", table.string(), "-o", again.string()}).exitCode, 0);
    const nlohmann::json m2 = readManifest(again);
    for (size_t i = 0; i < m.at("stimuli").size(); ++i)
        EXPECT_EQ(m.at("stimuli")[i].at("sha256"), m2.at("stimuli")[i].at("sha256")) << i;
}

TEST(StimuliImport, TomlTableWithBlocksIdsAndAnImagesFolder) {
    TempFolder folder("import-toml");
    const fs::path root = folder.path();
    for (const char* block : {"close", "mid"}) {
        const int w = std::string(block) == "close" ? 16 : 24; // blocks may differ in size
        for (int k = 0; k < 3; ++k)
            writeImage(root / "renders" / block / ("m" + std::to_string(k) + ".png"), w, 10, OIIO::TypeDesc::UINT8,
                       pattern(w, 10, k + (block[0] == 'm' ? 10 : 0)));
    }
    std::string text = "name = \"unreal-skin\"\ndescription = \"from elsewhere\"\nfactors = [\"method\", \"view\"]\n";
    for (const char* block : {"close", "mid"})
        for (int k = 0; k < 3; ++k)
            text += std::string("\n[[stimulus]]\nfile = \"") + block + "/m" + std::to_string(k) + ".png\"\nid = \"" +
                    block + "-m" + std::to_string(k) + "\"\nmethod = \"m" + std::to_string(k) + "\"\nview = \"" +
                    block + "\"\nblock = \"unreal/" + block + "\"\n" + (k == 0 ? "reference = true\n" : "");
    // The close reference takes its depth and mask from a skinlab-style EXR (R, G, B, depth.Z, mask.Y): the named
    // channels are used, not the first one.
    {
        auto aov = OIIO::ImageOutput::create((root / "renders" / "aov.exr").string());
        ASSERT_TRUE(aov);
        OIIO::ImageSpec spec(16, 10, 5, OIIO::TypeDesc::FLOAT);
        spec.channelnames = {"R", "G", "B", "depth.Z", "mask.Y"};
        std::vector<float> pixels;
        for (int i = 0; i < 16 * 10; ++i)
            pixels.insert(pixels.end(), {0.3f, 0.2f, 0.1f, 5.0f + i, i % 2 ? 1.0f : 0.0f});
        ASSERT_TRUE(aov->open((root / "renders" / "aov.exr").string(), spec));
        ASSERT_TRUE(aov->write_image(OIIO::TypeDesc::FLOAT, pixels.data()));
        ASSERT_TRUE(aov->close());
    }
    text.replace(text.find("reference = true\n"), 17,
                 "reference = true\ndepth = \"aov.exr\"\nmask = \"aov.exr\"\nf_px = 12.5\nmm_per_unit = 1000\n"
                 "sss_radius_mm = 2\n");
    const fs::path table = writeText(root / "tables", "t.toml", text);
    const fs::path out = root / "set";
    CommandResult r = runSkinlab({"stimuli", "import", table.string(), "-o", out.string(), "--images",
                                  (root / "renders").string(), "--no-contact-sheet", "--no-predict"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const nlohmann::json m = readManifest(out);
    EXPECT_EQ(m.at("set"), "unreal-skin");
    EXPECT_EQ(m.at("description"), "from elsewhere");
    EXPECT_EQ(m.at("stimuli").size(), 6u);
    EXPECT_FALSE(fs::exists(out / "contact.html"));
    const auto& s = entry(m, "mid-m0");
    EXPECT_EQ(s.at("block"), "unreal/mid");
    EXPECT_EQ(s.at("reference"), true);
    EXPECT_EQ(s.at("width"), 24);
    EXPECT_EQ(s.at("factors"), nlohmann::json({{"method", "m0"}, {"view", "mid"}}));
    EXPECT_EQ(entry(m, "close-m2").at("width"), 16);
    const auto& closeReference = entry(m, "close-m0");
    EXPECT_EQ(closeReference.at("provenance").at("depth"), "aov.exr");
    EXPECT_EQ(closeReference.at("provenance").at("f_px"), 12.5);
    {
        auto exr = OIIO::ImageInput::open((out / "exr" / "close-m0.exr").string());
        ASSERT_TRUE(exr);
        const OIIO::ImageSpec& spec = exr->spec();
        ASSERT_EQ(spec.channelnames, (std::vector<std::string>{"R", "G", "B", "depth.Z", "mask.Y"}));
        EXPECT_FLOAT_EQ(spec.get_float_attribute("skinlab:f_px"), 12.5f);
        EXPECT_FLOAT_EQ(spec.get_float_attribute("skinlab:mm_per_unit"), 1000.0f);
        EXPECT_FLOAT_EQ(spec.get_float_attribute("skinlab:sss_radius_mm"), 2.0f);
        std::vector<float> pixels(16 * 10 * 5);
        ASSERT_TRUE(exr->read_image(0, 0, 0, 5, OIIO::TypeDesc::FLOAT, pixels.data()));
        for (int i = 0; i < 16 * 10; ++i) {
            ASSERT_EQ(pixels[static_cast<size_t>(i * 5 + 3)], 5.0f + i) << i;
            ASSERT_EQ(pixels[static_cast<size_t>(i * 5 + 4)], i % 2 ? 1.0f : 0.0f) << i;
        }
    }
    EXPECT_FALSE(entry(m, "close-m1").at("provenance").contains("depth"));
    EXPECT_FALSE(s.contains("predicted"));
    expectHashes(out, m);

    // --name wins over the table's name; a folder holding another set is refused.
    CommandResult other = runSkinlab({"stimuli", "import", table.string(), "-o", out.string(), "--images",
                                      (root / "renders").string(), "--name", "renamed"});
    EXPECT_EQ(other.exitCode, 2);
    EXPECT_EQ(other.err, "skinlab: error: " + out.string() +
                             ": holds stimulus set 'unreal-skin', not 'renamed'; choose another folder\n");
}

// Each bad table: exit code 2, exactly one line naming the table, the line and the column, nothing written.
TEST(StimuliImport, RefusesBadTablesWithOneLineAndWritesNothing) {
    TempFolder folder("import-bad");
    const fs::path root = folder.path();
    writeImage(root / "a.png", 8, 6, OIIO::TypeDesc::UINT8, pattern(8, 6, 1));
    writeImage(root / "b.png", 8, 6, OIIO::TypeDesc::UINT8, pattern(8, 6, 2));
    writeImage(root / "wide.png", 9, 6, OIIO::TypeDesc::UINT8, pattern(9, 6, 3));
    writeImage(root / "lin.exr", 8, 6, OIIO::TypeDesc::FLOAT, pattern(8, 6, 4));
    writeText(root, "text.png", "this is not a picture\n");
    writeImage(root / "sub" / "a.png", 8, 6, OIIO::TypeDesc::UINT8, pattern(8, 6, 5));
    struct Case {
        std::string name, text, message; // message after "skinlab: error: TABLE"
    };
    const std::vector<Case> cases = {
        {"missing.csv", "file,factor:method\na.png,x\nnope.png,y\n",
         ":3: file: 'nope.png' not found (" + (root / "nope.png").string() + ")"},
        {"unknown.csv", "file,methd\na.png,x\n",
         ":1: methd: unknown column (the columns are file, id, block, reference, encoding, exposure_ev, depth, "
         "mask, f_px, mm_per_unit, sss_radius_mm and factor columns (CSV: factor:NAME; TOML: listed in `factors`))"},
        {"unknown.toml", "factors = [\"method\"]\n[[stimulus]]\nfile = \"a.png\"\nmethod = \"x\"\nmethd = \"y\"\n",
         ":5: methd: unknown column (the columns are file, id, block, reference, encoding, exposure_ev, depth, "
         "mask, f_px, mm_per_unit, sss_radius_mm and factor columns (CSV: factor:NAME; TOML: listed in `factors`))"},
        {"dup.csv", "file,id\na.png,same\nb.png,same\n", ":3: id: the id 'same' is also the id of line 2"},
        {"dupderived.csv", "file\na.png\nsub/a.png\n",
         ":3: file: the id 'a' is also the id of line 2 (give an id column)"},
        {"tworefs.csv", "file,block,reference\na.png,x,true\nb.png,y,true\nlin.exr,x,1\n",
         ":4: reference: block 'x' already has its reference on line 2"},
        {"tworefs.toml",
         "[[stimulus]]\nfile = \"a.png\"\nreference = true\n\n[[stimulus]]\nfile = \"b.png\"\nreference = true\n",
         ":7: reference: block 'tworefs' already has its reference on line 3"},
        {"sizes.csv", "file,block\na.png,x\nwide.png,y\nb.png,y\n",
         ":4: file: 'b.png' is 8x6, block 'y' holds 9x6 images (line 3); crop or scale them alike first"},
        {"encoding.csv", "file,encoding\na.png,sRGB-ish\n", ":2: encoding: 'sRGB-ish' is not one of srgb, linear"},
        {"exposure.csv", "file,exposure_ev\nlin.exr,bright\n", ":2: exposure_ev: 'bright' is not a number"},
        {"exposure.toml", "[[stimulus]]\nfile = \"lin.exr\"\n\nexposure_ev = \"1\"\n",
         ":4: exposure_ev: '\"1\"' is not a number"},
        {"exposuresrgb.csv", "file,exposure_ev\na.png,1\n",
         ":2: exposure_ev: applies to linear images only ('a.png' is sRGB)"},
        {"reference.csv", "file,reference\na.png,maybe\n", ":2: reference: 'maybe' is not true or false"},
        {"depthalone.csv", "file,depth\na.png,lin.exr\n", ":2: mask: depth and mask images are given together"},
        {"nocamera.csv", "file,depth,mask,f_px\na.png,lin.exr,b.png,40\n",
         ":2: mm_per_unit: a depth image needs f_px, mm_per_unit and sss_radius_mm (the camera and kernel of "
         "the metrics' bands)"},
        {"cameraalone.csv", "file,f_px\na.png,40\n", ":2: f_px: applies only with depth and mask images"},
        {"camerabad.toml",
         "[[stimulus]]\nfile = \"a.png\"\ndepth = \"lin.exr\"\nmask = \"b.png\"\nf_px = 40\nmm_per_unit = "
         "\"1\"\nsss_radius_mm = 1\n",
         ":6: mm_per_unit: '\"1\"' is not a number"},
        {"cameranegative.csv", "file,depth,mask,f_px,mm_per_unit,sss_radius_mm\na.png,lin.exr,b.png,40,-2,1\n",
         ":2: mm_per_unit: -2.000000 is not a positive number"},
        {"masksize.csv", "file,depth,mask,f_px,mm_per_unit,sss_radius_mm\na.png,lin.exr,wide.png,40,1,1\n",
         ":2: mask: 'wide.png' is 9x6, its image 'a.png' 8x6"},
        {"masknotfound.csv", "file,depth,mask,f_px,mm_per_unit,sss_radius_mm\na.png,lin.exr,m.png,40,1,1\n",
         ":2: mask: 'm.png' not found (" + (root / "m.png").string() + ")"},
        {"badid.csv", "file,id\na.png,A B\n", ":2: id: 'A B' is not an id (a-z 0-9 . _ -)"},
        {"fields.csv", "file,id\na.png\n", ":2: the row has 1 fields, the header 2"},
        {"nofile.csv", "id,factor:method\nx,y\n", ":1: file: the header has no 'file' column"},
        {"factorname.toml", "factors = [\"method\", \"file\"]\n[[stimulus]]\nfile = \"a.png\"\n",
         ":1: factors: 'file' is a reserved column, not a factor name"},
    };
    for (const Case& c : cases) {
        const fs::path table = writeText(root, c.name, c.text);
        const fs::path out = root / ("out-" + c.name);
        CommandResult r = runSkinlab({"stimuli", "import", table.string(), "-o", out.string()});
        EXPECT_EQ(r.exitCode, 2) << c.name << ": " << r.out << r.err;
        EXPECT_EQ(r.err, "skinlab: error: " + table.string() + c.message + "\n") << c.name;
        EXPECT_FALSE(fs::exists(out)) << c.name << ": something was written";
    }
    // An unreadable image: the reason comes from OpenImageIO, the rest is fixed; one line.
    const fs::path table = writeText(root, "unreadable.csv", "file\na.png\ntext.png\n");
    CommandResult r = runSkinlab({"stimuli", "import", table.string(), "-o", (root / "out-unreadable").string()});
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_EQ(r.err.rfind("skinlab: error: " + table.string() + ":3: file: 'text.png' is not a readable image (", 0),
              0u)
        << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(root / "out-unreadable"));
}

// An imported set is a set like a built one: a study of it runs, is analysed, and reported with image metrics
// against the imported references.
TEST(StimuliImport, ImportedSetThroughStudyAnalysisAndReport) {
    TempFolder folder("import-e2e");
    const fs::path root = folder.path();
    const int w = 32, h = 24;
    // Block a's reference carries a depth image and a skin mask (the left half), so its metrics have bands; block
    // b's reference is a plain image (image-wide metrics).
    writeImage(root / "img" / "depth.exr", w, h, OIIO::TypeDesc::FLOAT, std::vector<float>(w * h * 3, 2.0f));
    std::vector<float> mask(w * h * 3, 0.0f);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w / 2; ++x)
            for (int c = 0; c < 3; ++c) mask[static_cast<size_t>((y * w + x) * 3 + c)] = 1.0f;
    writeImage(root / "img" / "mask.png", w, h, OIIO::TypeDesc::UINT8, mask);
    std::string csv =
        "file,id,block,reference,factor:method,factor:quality,depth,mask,f_px,mm_per_unit,sss_radius_mm\n";
    for (const char* block : {"a", "b"}) {
        for (int k = 0; k < 3; ++k) {
            const std::string id = std::string(block) + "-q" + std::to_string(k);
            // Further from the reference with a lower quality: noise of growing amplitude.
            std::vector<float> rgb = pattern(w, h, block[0] == 'a' ? 0 : 7, 0.6f);
            for (size_t i = 0; i < rgb.size(); ++i) rgb[i] += 0.05f * static_cast<float>((2 - k) * ((i * 7) % 5));
            writeImage(root / "img" / (id + ".exr"), w, h, OIIO::TypeDesc::FLOAT, rgb);
            csv += "img/" + id + ".exr," + id + "," + block + ",,m" + std::to_string(k) + "," + std::to_string(k) +
                   ",,,,,\n";
        }
        writeImage(root / "img" / (std::string(block) + "-ref.exr"), w, h, OIIO::TypeDesc::FLOAT,
                   pattern(w, h, block[0] == 'a' ? 0 : 7, 0.6f));
        csv += std::string("img/") + block + "-ref.exr," + block + "-ref," + block + ",true,reference,3," +
               (block[0] == 'a' ? "img/depth.exr,img/mask.png,40,10,2\n" : ",,,,\n");
    }
    const fs::path table = writeText(root, "engine.csv", csv);
    const fs::path set = root / "set";
    CommandResult imported = runSkinlab({"stimuli", "import", table.string(), "-o", set.string()});
    ASSERT_EQ(imported.exitCode, 0) << imported.err;

    const fs::path design = writeText(root, "design.toml",
                                      "title = \"imported\"\nseed = 3\nrepetitions = 1\nconditions = [\"m0\", \"m1\", "
                                      "\"m2\"]\n[practice]\ntrials = 0\n[catch]\nblank = 0\n");
    const fs::path study = root / "study.db";
    CommandResult created =
        runSkinlab({"study", "create", "--stimuli", set.string(), "--design", design.string(), "-o", study.string()});
    ASSERT_EQ(created.exitCode, 0) << created.out << created.err;

    ChildProcess server(
        {SKINLAB_CLI, "study", "serve", study.string(), "--port", "0", "--token", "researcher-token-0123456789"});
    int port = -1;
    static const std::regex serving(R"(serving .* on http://127\.0\.0\.1:(\d+)/)");
    for (int i = 0; i < 10 && port < 0; ++i) {
        bool ok = false;
        const std::string line = server.readLine(std::chrono::seconds(20), ok);
        if (!ok) break;
        std::smatch match;
        if (std::regex_search(line, match, serving)) port = std::stoi(match[1].str());
    }
    ASSERT_GT(port, 0) << "the server did not start";
    CommandResult simulated = runSkinlab({"study", "simulate", study.string(), "--observer-count", "6", "--url",
                                          "http://127.0.0.1:" + std::to_string(port), "--truth-factor", "quality"});
    ASSERT_EQ(simulated.exitCode, 0) << simulated.out << simulated.err;
    EXPECT_NE(simulated.out.find("6/6 observers completed"), std::string::npos) << simulated.out;
    server.kill(SIGTERM);
    server.wait();

    const fs::path responses = root / "responses.csv";
    CommandResult exported =
        runSkinlab({"study", "export", study.string(), "--format", "csv", "-o", responses.string()});
    ASSERT_EQ(exported.exitCode, 0) << exported.err;
    CommandResult scaled =
        runSkinlab({"analyze", "scale", responses.string(), "-o", (root / "scale").string(), "--bootstrap", "100"});
    ASSERT_EQ(scaled.exitCode, 0) << scaled.out << scaled.err;

    const fs::path report = root / "report";
    CommandResult reported =
        runSkinlab({"report", study.string(), "-o", report.string(), "--no-pdf", "--bootstrap", "100"});
    ASSERT_EQ(reported.exitCode, 0) << reported.out << reported.err;
    EXPECT_TRUE(fs::is_regular_file(report / "index.html"));
    // The metrics were computed against each block's imported reference, for every condition of the study.
    ASSERT_TRUE(fs::is_regular_file(report / "metrics" / "metrics.json")) << reported.err;
    const nlohmann::json metrics = nlohmann::json::parse(skinlab::readFile(report / "metrics" / "metrics.json"));
    const std::string text = metrics.dump();
    for (const char* id : {"a-q0", "a-q1", "a-q2", "b-q0", "b-q1", "b-q2"})
        EXPECT_NE(text.find(id), std::string::npos) << id;
    EXPECT_NE(text.find("a-ref"), std::string::npos);
    EXPECT_NE(text.find("b-ref"), std::string::npos);
    ASSERT_EQ(metrics.at("comparisons").size(), 6u);
    for (const auto& c : metrics.at("comparisons")) EXPECT_EQ(c.at("bands_measured"), c.at("block") == "a") << c.dump();
    // Three conditions a block: the metrics' correlations have no interval, and the page says why (not "[—, —]").
    const std::string page = skinlab::readFile(report / "index.html");
    EXPECT_EQ(page.find("[—, —]"), std::string::npos);
    EXPECT_NE(page.find("(no interval with 3 conditions: Fisher z needs 4)"), std::string::npos);
}
