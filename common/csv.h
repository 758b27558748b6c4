#pragma once
// CSV (RFC 4180, https://www.rfc-editor.org/rfc/rfc4180): the one reader and the one field writer of every CSV file
// skinlab reads or writes (responses, manifests, metrics, scales, imported tables).
#include <string>
#include <string_view>
#include <vector>

namespace skinlab {

struct CsvRecord {
    int line = 0; // 1-based line number in the file
    std::vector<std::string> fields;
};

// Splits `text` into records, skipping blank lines: comma-separated fields, optional double quotes ("" escapes a
// quote), LF or CRLF line ends; a quoted field may hold commas, quotes and line breaks (a record then spans lines).
// Spaces and tabs around an unquoted field are trimmed; a UTF-8 byte-order mark is skipped. `file` names the file in
// errors (unterminated quote).
std::vector<CsvRecord> parseCsv(std::string_view text, const std::string& file);

// One CSV field: quoted, with inner quotes doubled, when it holds a comma, a quote or a line break, or starts or
// ends with a space or tab (which parseCsv and other readers trim from unquoted fields); as it is otherwise.
std::string csvField(std::string_view text);

} // namespace skinlab
