#pragma once
// A fresh folder for one test's files, removed when the object goes out of scope (unless `keep` is set, to look at
// the files after a failure). It lies under the build folder's tests-tmp/, named by a tag (by default the running
// test's suite and name), the process id and a counter, so that tests run as parallel processes (ctest -j) and two
// folders of one test never share files.
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <string>
#include <unistd.h>

namespace skinlab::test_support {

class TempFolder {
public:
    explicit TempFolder(const std::string& tag = currentTestName()) {
        static int counter = 0;
        path_ = std::filesystem::path(SKINLAB_BINARY_DIR) / "tests-tmp" /
                (tag + "-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
        std::filesystem::remove_all(path_);
        std::filesystem::create_directories(path_);
    }
    ~TempFolder() {
        std::error_code ignored;
        if (!keep) std::filesystem::remove_all(path_, ignored);
    }
    TempFolder(const TempFolder&) = delete;
    TempFolder& operator=(const TempFolder&) = delete;

    const std::filesystem::path& path() const { return path_; }
    std::filesystem::path operator/(const std::string& name) const { return path_ / name; }
    // Writes `content` (bytes as given) to the file `name` in the folder and returns its path.
    std::filesystem::path write(const std::string& name, const std::string& content) const {
        const std::filesystem::path file = path_ / name;
        std::ofstream(file, std::ios::binary) << content;
        return file;
    }
    bool keep = false;

private:
    static std::string currentTestName() {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        return info ? std::string(info->test_suite_name()) + "-" + info->name() : "test";
    }
    std::filesystem::path path_;
};

} // namespace skinlab::test_support
