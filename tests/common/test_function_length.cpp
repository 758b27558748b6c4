// No production function is over 120 lines (docs/architecture.md, "Long functions"): a brace-matching scan of the
// .cpp files of the production folders. A function is a brace block opened at namespace or class scope whose header
// (the text since the previous ';', '{', '}' or access label) holds a parameter list and no '=' before it; its length
// runs from the first line of that header to the closing brace. Comments, string and character literals (raw strings too) and preprocessor
// lines are skipped.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

constexpr int kMaxLines = 120;
constexpr int kListedFrom = 100; // functions this long or longer are printed (the table in docs/architecture.md)

struct LongFunction {
    std::string file;
    std::string name;
    int lines = 0;
};

// The source with comments, literals and preprocessor lines blanked (newlines kept, so line numbers hold).
std::string codeOnly(const std::string& text) {
    std::string out = text;
    std::size_t i = 0;
    bool lineStart = true;
    auto blank = [&](std::size_t from, std::size_t to) {
        for (std::size_t k = from; k < to && k < out.size(); ++k)
            if (out[k] != '\n') out[k] = ' ';
    };
    while (i < text.size()) {
        const char c = text[i];
        if (lineStart && c == '#') { // a preprocessor line, with its continuations
            std::size_t end = i;
            while (end < text.size() && !(text[end] == '\n' && text[end - 1] != '\\')) ++end;
            blank(i, end);
            i = end;
            continue;
        }
        if (c == '\n') lineStart = true;
        else if (c != ' ' && c != '\t') lineStart = false;
        if (c == '/' && i + 1 < text.size() && text[i + 1] == '/') {
            const std::size_t end = text.find('\n', i);
            blank(i, end == std::string::npos ? text.size() : end);
            i = end == std::string::npos ? text.size() : end;
        } else if (c == '/' && i + 1 < text.size() && text[i + 1] == '*') {
            const std::size_t end = text.find("*/", i + 2);
            const std::size_t stop = end == std::string::npos ? text.size() : end + 2;
            blank(i, stop);
            i = stop;
        } else if (c == 'R' && i + 1 < text.size() && text[i + 1] == '"' &&
                   (i == 0 || !(std::isalnum(static_cast<unsigned char>(text[i - 1])) || text[i - 1] == '_'))) {
            const std::size_t open = text.find('(', i + 2);
            const std::string close = ")" + text.substr(i + 2, open - i - 2) + "\"";
            const std::size_t end = text.find(close, open);
            const std::size_t stop = end == std::string::npos ? text.size() : end + close.size();
            blank(i, stop);
            i = stop;
        } else if (c == '"' ||
                   (c == '\'' && !(i > 0 && std::isxdigit(static_cast<unsigned char>(text[i - 1])) &&
                                   i + 1 < text.size() && std::isxdigit(static_cast<unsigned char>(text[i + 1]))))) {
            std::size_t k = i + 1; // a literal; a ' between digits is a digit separator
            while (k < text.size() && text[k] != c) k += text[k] == '\\' ? 2 : 1;
            blank(i, k + 1);
            i = k + 1;
        } else {
            ++i;
        }
    }
    return out;
}

// Whether a '{' ends `header` as part of a constructor's member initialiser list (`: a_(1), b_{2}`), not a body.
bool braceInitialiser(const std::string& header) {
    const std::size_t close = header.find(')');
    if (close == std::string::npos) return false;
    bool initialiserList = false;
    for (std::size_t k = close + 1; k < header.size(); ++k)
        if (header[k] == ':') {
            if (k + 1 < header.size() && header[k + 1] == ':') ++k;
            else initialiserList = true;
        }
    const std::size_t last = header.find_last_not_of(" \t\n");
    return initialiserList && last != std::string::npos &&
           (std::isalnum(static_cast<unsigned char>(header[last])) || header[last] == '_' || header[last] == '>');
}

// "public", "private" or "protected" (before a ':'), blanks around.
bool accessLabel(const std::string& text) {
    const std::size_t first = text.find_first_not_of(" \t\n"), last = text.find_last_not_of(" \t\n");
    if (first == std::string::npos) return false;
    const std::string word = text.substr(first, last - first + 1);
    return word == "public" || word == "private" || word == "protected";
}

enum class Block { scope, function, other }; // scope: a namespace, extern "C" or a class body

Block blockKind(const std::string& header) {
    auto word = [&](const char* w) {
        const std::string h = " " + header + " ";
        for (std::size_t at = h.find(w); at != std::string::npos; at = h.find(w, at + 1)) {
            const char before = h[at - 1], after = h[at + std::string(w).size()];
            if (!(std::isalnum(static_cast<unsigned char>(before)) || before == '_') &&
                !(std::isalnum(static_cast<unsigned char>(after)) || after == '_'))
                return true;
        }
        return false;
    };
    const std::size_t paren = header.find('(');
    if (word("namespace") || (word("extern") && paren == std::string::npos)) return Block::scope;
    if ((word("class") || word("struct") || word("union") || word("enum")) && paren == std::string::npos)
        return Block::scope;
    if (paren == std::string::npos) return Block::other;
    const std::size_t equals = header.find('=');
    if (equals != std::string::npos && equals < paren && !word("operator")) return Block::other; // = [..](..) {
    return Block::function;
}

std::vector<LongFunction> longFunctions(const fs::path& file, const std::string& shownName) {
    std::ifstream in(file, std::ios::binary);
    std::stringstream buffer;
    buffer << in.rdbuf();
    const std::string code = codeOnly(buffer.str());
    std::vector<int> lineOf(code.size() + 1, 1);
    for (std::size_t i = 0, line = 1; i < code.size(); ++i) {
        lineOf[i] = static_cast<int>(line);
        if (code[i] == '\n') ++line;
    }
    auto matchingBrace = [&](std::size_t open) {
        int depth = 0;
        for (std::size_t k = open; k < code.size(); ++k) {
            if (code[k] == '{') ++depth;
            else if (code[k] == '}' && --depth == 0) return k;
        }
        return code.size() - 1;
    };
    std::vector<LongFunction> out;
    std::vector<Block> open; // the blocks around the scan position (only scopes: functions are skipped whole)
    std::size_t headerStart = 0;
    for (std::size_t i = 0; i < code.size(); ++i) {
        const char c = code[i];
        if (c == ';' || (c == ':' && accessLabel(code.substr(headerStart, i - headerStart)))) {
            headerStart = i + 1;
            continue;
        }
        if (c == '}') {
            if (!open.empty()) open.pop_back();
            headerStart = i + 1;
            continue;
        }
        if (c != '{') continue;
        const std::string header = code.substr(headerStart, i - headerStart);
        if (braceInitialiser(header)) { // part of the header still
            i = matchingBrace(i);
            continue;
        }
        const Block kind = blockKind(header);
        if (kind == Block::scope) {
            open.push_back(kind);
            headerStart = i + 1;
            continue;
        }
        const std::size_t end = matchingBrace(i);
        if (kind == Block::function) {
            const std::size_t first = code.find_first_not_of(" \t\n", headerStart);
            const int lines = lineOf[end] - lineOf[first] + 1;
            std::string name = header.substr(0, header.find('('));
            name.erase(0, name.find_last_of(" \t\n*&") + 1);
            if (lines >= kListedFrom) out.push_back({shownName, name, lines});
        }
        i = end;
        headerStart = end + 1;
    }
    return out;
}

TEST(FunctionLength, NoProductionFunctionIsOver120Lines) {
    const fs::path root = SKINLAB_SOURCE_DIR;
    const std::vector<std::string> folders = {"common",   "net",    "renderer", "stimuli", "experiments",
                                              "analysis", "report", "tune",     "cli"};
    std::vector<LongFunction> all;
    for (const std::string& folder : folders)
        for (const auto& entry : fs::recursive_directory_iterator(root / folder))
            if (entry.is_regular_file() && entry.path().extension() == ".cpp") {
                const auto found = longFunctions(entry.path(), fs::relative(entry.path(), root).generic_string());
                all.insert(all.end(), found.begin(), found.end());
            }
    std::sort(all.begin(), all.end(), [](const auto& a, const auto& b) { return a.lines > b.lines; });
    for (const LongFunction& f : all) {
        std::printf("%4d  %s  %s\n", f.lines, f.name.c_str(), f.file.c_str());
        if (f.lines > kMaxLines)
            ADD_FAILURE() << f.file << ": " << f.name << " is " << f.lines << " lines (at most " << kMaxLines
                          << "): split it into helpers";
    }
}

// The scanner itself: a known layout measured as clang-format writes it.
TEST(FunctionLength, ScannerMeasuresFunctionsNotNamespacesOrTables) {
    const fs::path file = fs::path(SKINLAB_BINARY_DIR) / "tests-tmp" / "function_length_sample.cpp";
    fs::create_directories(file.parent_path());
    std::string body;
    for (int k = 0; k < 101; ++k) body += "    x += \"}{\"[0]; // {\n";
    {
        std::ofstream out(file, std::ios::binary);
        out << "#include <x>\nnamespace a {\nconst int table[] = {\n1, 2};\nstruct S {\n    S() : a_{1} {}\n"
            << "public:\n    void f() {\n"
            << body << "    }\n    int a_;\n};\nint longOne(int x,\n"
            << "            int y) {\n"
            << body << "    return R\"(}})\"[0];\n}\n} // namespace a\n";
    }
    const auto found = longFunctions(file, "sample.cpp");
    ASSERT_EQ(found.size(), 2u); // S::f (103 lines) and longOne
    EXPECT_EQ(found[0].name, "f");
    EXPECT_EQ(found[0].lines, 103);
    EXPECT_EQ(found[1].name, "longOne");
    EXPECT_EQ(found[1].lines, 105); // two header lines, 101 body lines, the return, the closing brace
}

} // namespace
