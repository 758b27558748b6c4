#include "common/csv.h"

#include "common/error.h"

namespace skinlab {

std::vector<CsvRecord> parseCsv(std::string_view text, const std::string& file) {
    std::vector<CsvRecord> records;
    size_t position = 0;
    // A UTF-8 byte-order mark (spreadsheet exports) is not part of the first column name.
    if (text.substr(0, 3) == "\xEF\xBB\xBF") position = 3;
    int line = 1; // line of the character at `position`
    while (position < text.size()) {
        CsvRecord record;
        record.line = line;
        std::string field;
        bool quoted = false;    // inside double quotes
        bool wasQuoted = false; // the current field had a quoted part (its spaces are kept)
        bool blank = true;      // only spaces and tabs so far
        int quoteLine = line;
        auto finishField = [&] {
            if (!wasQuoted) { // trim spaces around unquoted values
                const size_t first = field.find_first_not_of(" \t");
                const size_t last = field.find_last_not_of(" \t");
                field = first == std::string::npos ? std::string() : field.substr(first, last - first + 1);
            }
            record.fields.push_back(std::move(field));
            field.clear();
            wasQuoted = false;
        };
        bool ended = false;
        while (position < text.size() && !ended) {
            const char c = text[position++];
            if (quoted) {
                if (c == '"' && position < text.size() && text[position] == '"') {
                    field += '"';
                    ++position;
                } else if (c == '"') {
                    quoted = false;
                } else {
                    if (c == '\n') ++line; // a quoted line break is part of the field
                    field += c;
                }
                continue;
            }
            if (c == '"') {
                quoted = wasQuoted = true;
                blank = false;
                quoteLine = line;
            } else if (c == ',') {
                blank = false;
                finishField();
            } else if (c == '\n') {
                ++line;
                ended = true;
            } else if (c == '\r' && (position == text.size() || text[position] == '\n')) {
                // CR of a CRLF line end
            } else {
                if (c != ' ' && c != '\t') blank = false;
                field += c;
            }
        }
        if (quoted) throwInput(file, "line " + std::to_string(quoteLine), "unterminated double quote");
        if (blank) continue; // blank line
        finishField();
        records.push_back(std::move(record));
    }
    return records;
}

std::string csvField(std::string_view text) {
    const bool blankEdge =
        !text.empty() && (text.front() == ' ' || text.front() == '\t' || text.back() == ' ' || text.back() == '\t');
    if (!blankEdge && text.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(text);
    std::string quoted = "\"";
    for (char c : text) {
        if (c == '"') quoted += '"';
        quoted += c;
    }
    return quoted + "\"";
}

} // namespace skinlab
