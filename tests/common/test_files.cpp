#include "common/error.h"
#include "common/files.h"
#include "common/hash.h"

#include <filesystem>
#include <gtest/gtest.h>
#include <unistd.h>

namespace fs = std::filesystem;

TEST(Files, AtomicWriteReplacesAndLeavesNoTemporary) {
    fs::path dir = fs::temp_directory_path() / ("skinlab_test_files-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    skinlab::writeFileAtomic(dir / "a.txt", "first");
    skinlab::writeFileAtomic(dir / "a.txt", "second");
    EXPECT_EQ(skinlab::readFile(dir / "a.txt"), "second");
    int n = 0;
    for (auto& e : fs::directory_iterator(dir)) {
        (void)e;
        ++n;
    }
    EXPECT_EQ(n, 1);
    fs::remove_all(dir);
}

TEST(Files, UncommittedOutputIsRemoved) {
    fs::path dir = fs::temp_directory_path() / ("skinlab_test_files2-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    {
        skinlab::AtomicOutput out(dir / "b.bin");
        skinlab::writeFileAtomic(out.tempPath(), "partial");
        EXPECT_TRUE(fs::exists(out.tempPath()));
    }
    EXPECT_FALSE(fs::exists(dir / "b.bin"));
    EXPECT_TRUE(fs::is_empty(dir));
    fs::remove_all(dir);
}

TEST(Files, UnreadableFileNamesThePath) {
    try {
        skinlab::readFile("/nonexistent/skinlab.toml");
        FAIL() << "no exception";
    } catch (const skinlab::InputError& e) {
        EXPECT_EQ(std::string(e.what()).rfind("/nonexistent/skinlab.toml: cannot read file", 0), 0u) << e.what();
    }
}

TEST(Hash, Sha256KnownVector) {
    EXPECT_EQ(skinlab::sha256Hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
}
