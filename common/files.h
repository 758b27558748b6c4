#pragma once
// Atomic outputs: nothing half-written ever appears under a final name. Write to a temporary file in the same
// folder (same file system, so rename(2) is atomic), then rename over the final name.
#include <filesystem>
#include <string>
#include <string_view>

namespace skinlab {

// Writes `data` to `path` atomically (temp file + fsync + rename). Throws InputError if the folder is not writable.
void writeFileAtomic(const std::filesystem::path& path, std::string_view data);

// Reads a whole file; throws InputError naming the file when it cannot be read.
std::string readFile(const std::filesystem::path& path);

// A temporary sibling of a final path. Write to tempPath() with any library (OpenImageIO, OpenCV, ...), then
// commit(); if commit() is never called the temporary file is removed on destruction.
class AtomicOutput {
public:
    explicit AtomicOutput(std::filesystem::path finalPath);
    ~AtomicOutput();
    AtomicOutput(const AtomicOutput&) = delete;
    AtomicOutput& operator=(const AtomicOutput&) = delete;

    const std::filesystem::path& tempPath() const { return temp_; }
    const std::filesystem::path& finalPath() const { return final_; }
    // fsyncs the temporary file and renames it over the final path.
    void commit();

private:
    std::filesystem::path final_;
    std::filesystem::path temp_;
    bool committed_ = false;
};

// Creates `dir` (and parents) or throws InputError naming it.
void ensureDirectory(const std::filesystem::path& dir);

} // namespace skinlab
