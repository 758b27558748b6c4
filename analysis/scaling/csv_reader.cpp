#include "analysis/scaling/csv_reader.h"

#include "common/error.h"

namespace skinlab::analysis::scaling {

std::vector<CsvRecord> parseCsv(std::string_view text, const std::string& file) {
    std::vector<CsvRecord> records;
    int line = 0;
    size_t position = 0;
    // A UTF-8 byte-order mark (spreadsheet exports) is not part of the first column name.
    if (text.substr(0, 3) == "\xEF\xBB\xBF") position = 3;
    while (position < text.size()) {
        ++line;
        size_t end = text.find('\n', position);
        if (end == std::string_view::npos) end = text.size();
        std::string_view row = text.substr(position, end - position);
        position = end + 1;
        if (!row.empty() && row.back() == '\r') row.remove_suffix(1);
        if (row.find_first_not_of(" \t") == std::string_view::npos) continue;
        CsvRecord record;
        record.line = line;
        std::string field;
        bool quoted = false;
        for (size_t k = 0; k < row.size(); ++k) {
            const char c = row[k];
            if (quoted) {
                if (c == '"' && k + 1 < row.size() && row[k + 1] == '"') {
                    field += '"';
                    ++k;
                } else if (c == '"') {
                    quoted = false;
                } else {
                    field += c;
                }
            } else if (c == '"') {
                quoted = true;
            } else if (c == ',') {
                record.fields.push_back(std::move(field));
                field.clear();
            } else {
                field += c;
            }
        }
        if (quoted) throwInput(file, "line " + std::to_string(line), "unterminated double quote");
        record.fields.push_back(std::move(field));
        for (auto& value : record.fields) {  // trim spaces around unquoted values
            const size_t first = value.find_first_not_of(" \t");
            const size_t last = value.find_last_not_of(" \t");
            value = first == std::string::npos ? std::string() : value.substr(first, last - first + 1);
        }
        records.push_back(std::move(record));
    }
    return records;
}

std::string csvField(std::string_view value) {
    if (value.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(value);
    std::string out = "\"";
    for (char c : value) {
        if (c == '"') out += '"';
        out += c;
    }
    return out + '"';
}

} // namespace skinlab::analysis::scaling
