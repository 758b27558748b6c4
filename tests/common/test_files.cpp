#include "common/error.h"
#include "common/files.h"
#include "common/hash.h"
#include "tests/common/temp_folder.h"

#include <filesystem>
#include <gtest/gtest.h>
#include <unistd.h>

namespace fs = std::filesystem;

TEST(Files, AtomicWriteReplacesAndLeavesNoTemporary) {
    const skinlab::test_support::TempFolder folder;
    const fs::path dir = folder / "out"; // absent: the write creates it
    skinlab::writeFileAtomic(dir / "a.txt", "first");
    skinlab::writeFileAtomic(dir / "a.txt", "second");
    EXPECT_EQ(skinlab::readFile(dir / "a.txt"), "second");
    int n = 0;
    for (auto& e : fs::directory_iterator(dir)) {
        (void)e;
        ++n;
    }
    EXPECT_EQ(n, 1);
}

TEST(Files, UncommittedOutputIsRemoved) {
    const skinlab::test_support::TempFolder folder;
    const fs::path dir = folder / "out";
    {
        skinlab::AtomicOutput out(dir / "b.bin");
        skinlab::writeFileAtomic(out.tempPath(), "partial");
        EXPECT_TRUE(fs::exists(out.tempPath()));
    }
    EXPECT_FALSE(fs::exists(dir / "b.bin"));
    EXPECT_TRUE(fs::is_empty(dir));
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
