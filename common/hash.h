#pragma once
#include <filesystem>
#include <string>
#include <string_view>

namespace skinlab {

// Lower-case hex SHA-256 (OpenSSL EVP).
std::string sha256Hex(std::string_view data);
// SHA-256 of a file's bytes; throws InputError naming the file when it cannot be read.
std::string sha256File(const std::filesystem::path& path);

} // namespace skinlab
