// A method is one unit (docs/methods.md, "Adding a method"): code asks its row or its class, not its name, so a
// built-in method's name appears in at most three production files (the C++ sources and the web pages of the
// production folders; tests and docs aside). A file counts for a method when it holds the name as a string literal
// (comments skipped) in the method's own file under renderer/sss/methods/, or elsewhere on a line that speaks of a
// method ("method" in its code, e.g. `method == "eevee"`, `value("method", "none")`). The condition on the line keeps
// the other meanings of some names out of the count: "none" as the off value of many choices, "reference" as a
// stimulus block's reference, "pathtraced" and "eevee" as the names of their spec tables and Blender's engines.
#include "renderer/sss/sss_params.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

constexpr std::size_t kMaxFiles = 3;

struct Literal {
    std::string text;
    std::string line; // the rest of its line (its code, other literals' contents included)
};

bool hexDigit(char c) { return std::isxdigit(static_cast<unsigned char>(c)) != 0; }

// The string literals of a source (C++: "..." and raw strings; web pages: "...", '...' and `...`), comments skipped.
std::vector<Literal> literals(const std::string& text, bool web) {
    std::vector<Literal> out;
    const auto lineAround = [&](std::size_t from, std::size_t to) {
        const std::size_t start = text.rfind('\n', from) == std::string::npos ? 0 : text.rfind('\n', from) + 1;
        const std::size_t end = std::min(text.find('\n', to), text.size());
        return text.substr(start, from - start) + text.substr(to, end - to);
    };
    std::size_t i = 0;
    while (i < text.size()) {
        const char c = text[i];
        if (text.compare(i, 2, "//") == 0) {
            i = std::min(text.find('\n', i), text.size());
        } else if (text.compare(i, 2, "/*") == 0 || (web && text.compare(i, 4, "<!--") == 0)) {
            const std::string close = text[i] == '/' ? "*/" : "-->";
            const std::size_t end = text.find(close, i + 2);
            i = end == std::string::npos ? text.size() : end + close.size();
        } else if (!web && c == 'R' && text.compare(i + 1, 1, "\"") == 0 &&
                   (i == 0 || !(std::isalnum(static_cast<unsigned char>(text[i - 1])) || text[i - 1] == '_'))) {
            const std::size_t open = text.find('(', i + 2);
            const std::string close = ")" + text.substr(i + 2, open - i - 2) + "\"";
            const std::size_t end = text.find(close, open);
            i = end == std::string::npos ? text.size() : end + close.size();
        } else if (c == '"' || (web && c == '`') ||
                   (c == '\'' && !(i > 0 && hexDigit(text[i - 1]) && i + 1 < text.size() && hexDigit(text[i + 1])))) {
            std::size_t k = i + 1; // a literal; a ' between digits is a digit separator
            while (k < text.size() && text[k] != c) k += text[k] == '\\' ? 2 : 1;
            k = std::min(k, text.size());
            out.push_back({text.substr(i + 1, k - i - 1), lineAround(i, std::min(k + 1, text.size()))});
            i = k + 1;
        } else {
            ++i;
        }
    }
    return out;
}

bool speaksOfAMethod(const std::string& line) {
    std::string lower = line;
    std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char ch) { return std::tolower(ch); });
    return lower.find("method") != std::string::npos;
}

// Files (relative to the source folder) that name `name` as a method, by the rule above.
std::map<std::string, std::set<std::string>> filesNamingMethods(const fs::path& root,
                                                                const std::vector<std::string>& names) {
    const std::vector<std::string> folders = {"common",      "net",      "formats", "renderer", "stimuli",
                                              "experiments", "analysis", "report",  "tune",     "cli"};
    const std::set<std::string> extensions = {".cpp", ".h", ".js", ".mjs", ".html"};
    std::map<std::string, std::set<std::string>> files;
    for (const std::string& folder : folders)
        for (const auto& entry : fs::recursive_directory_iterator(root / folder)) {
            const std::string extension = entry.path().extension().string();
            if (!entry.is_regular_file() || !extensions.count(extension)) continue;
            const std::string shown = fs::relative(entry.path(), root).generic_string();
            const bool ownFile = shown.rfind("renderer/sss/methods/", 0) == 0;
            std::ifstream in(entry.path(), std::ios::binary);
            std::stringstream buffer;
            buffer << in.rdbuf();
            for (const Literal& literal : literals(buffer.str(), extension != ".cpp" && extension != ".h"))
                if (std::find(names.begin(), names.end(), literal.text) != names.end() &&
                    (ownFile || speaksOfAMethod(literal.line)))
                    files[literal.text].insert(shown);
        }
    return files;
}

} // namespace

TEST(MethodNames, EachBuiltInNameIsInAtMostThreeProductionFiles) {
    std::vector<std::string> names = skinlab::renderer::sss::methodNames();
    ASSERT_FALSE(names.empty());
    const auto files = filesNamingMethods(SKINLAB_SOURCE_DIR, names);
    for (const std::string& name : names) {
        const auto found = files.find(name);
        ASSERT_NE(found, files.end()) << name << ": its own file does not name it (the scan is broken)";
        std::string list;
        for (const std::string& file : found->second) list += " " + file;
        std::printf("%-14s %zu:%s\n", name.c_str(), found->second.size(), list.c_str());
        EXPECT_LE(found->second.size(), kMaxFiles)
            << "'" << name << "' is named as a method in" << list << ": ask its row or its class instead";
    }
}

// The scanner: literals in code count, comments do not, and a line must speak of a method outside the method files.
TEST(MethodNames, ScannerCountsLiteralsOnMethodLinesOnly) {
    const fs::path root = fs::path(SKINLAB_BINARY_DIR) / "tests-tmp" / "method_names_sample";
    fs::remove_all(root);
    fs::create_directories(root / "renderer/sss/methods");
    fs::create_directories(root / "tune/web");
    std::ofstream(root / "renderer/sss/methods/box.cpp") << "// \"box\" in a comment\nreturn {{}, \"box\", 1};\n";
    std::ofstream(root / "renderer/compare.cpp")
        << "if (method == \"box\") f(); /* method \"tent\" */\nif (mode == \"box\") g();\nauto s = R\"(\"tent\")\";\n";
    std::ofstream(root / "tune/web/app.js") << "const m = valueAt('sss.method') || 'tent'; // \"box\"\n";
    for (const char* folder : {"common", "net", "formats", "stimuli", "experiments", "analysis", "report", "cli"})
        fs::create_directories(root / folder);
    const auto files = filesNamingMethods(root, {"box", "tent"});
    EXPECT_EQ(files.at("box"), (std::set<std::string>{"renderer/compare.cpp", "renderer/sss/methods/box.cpp"}));
    EXPECT_EQ(files.at("tent"), (std::set<std::string>{"tune/web/app.js"}));
}
