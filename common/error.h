#pragma once
// skinlab's error policy (docs/architecture.md, "Errors"):
//  - bad input (spec, asset, request, command-line value): throw InputError with a one-line message that names
//    the file, key and value at fault; the CLI prints it and exits 2, the server answers 4xx JSON;
//  - driver / EGL / GL / I/O failures outside the user's control: throw RuntimeError (CLI exit 1);
//  - bugs: SKINLAB_CHECK / SKINLAB_CHECK_EQ … of common/check.h (always on, also in release builds; prints
//    the expression and both values, then aborts).
// Never print and carry on.
#include <stdexcept>
#include <string>
#include <string_view>

namespace skinlab {

class Error : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// Bad input from the user: one line, naming what and where ("scene.toml: camera.fov_deg: 200 is out of range [1, 179]").
class InputError : public Error {
public:
    using Error::Error;
};

// Failure of the environment: GPU driver, EGL, GL, the file system.
class RuntimeError : public Error {
public:
    using Error::Error;
};

// "<where>: <key>: <message>" with empty parts left out.
std::string contextMessage(std::string_view where, std::string_view key, std::string_view message);

[[noreturn]] void throwInput(std::string_view where, std::string_view key, std::string_view message);

} // namespace skinlab
