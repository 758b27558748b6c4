#pragma once
// Minimal RFC 4180 CSV reading: comma-separated fields, optional double quotes ("" escapes a quote), LF or
// CRLF line ends; a quoted field may hold commas, quotes and line breaks (a record then spans lines).
#include <string>
#include <string_view>
#include <vector>

namespace skinlab::analysis::scaling {

struct CsvRecord {
    int line = 0; // 1-based line number in the file
    std::vector<std::string> fields;
};

// Splits `text` into records, skipping blank lines. `file` names the file in errors (unterminated quote).
std::vector<CsvRecord> parseCsv(std::string_view text, const std::string& file);

// Quotes a field for writing when it contains a comma, quote or line break.
std::string csvField(std::string_view value);

} // namespace skinlab::analysis::scaling
