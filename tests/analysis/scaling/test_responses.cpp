// Reading responses: every accepted format, and the exact one-line error for each kind of bad input.
#include "analysis/scaling/comparison_data.h"
#include "analysis/scaling/responses.h"
#include "common/error.h"

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <filesystem>
#include <fstream>

namespace skinlab::analysis::scaling {
namespace {

std::filesystem::path scratch() {
    const auto folder = std::filesystem::path(SKINLAB_BINARY_DIR) / "test-scratch" / "scaling";
    std::filesystem::create_directories(folder);
    return folder;
}

std::string writeText(const std::string& name, const std::string& text) {
    const auto path = scratch() / name;
    std::ofstream(path, std::ios::binary) << text;
    return path.string();
}

// The message of the InputError thrown by reading (and grouping) `path`, or "" if none.
std::string errorOf(const std::string& path, const DatasetOptions& options = {}) {
    try {
        buildDataset(readResponses(path), options);
    } catch (const InputError& error) {
        return error.what();
    }
    return "";
}

const std::string kPwcmpHeader = "observer,scene,condition_A,condition_B,is_A_selected\n";

TEST(Responses, UnknownConditionInACountMatrix) {
    const std::string path = writeText("unknown.csv", "condition,a,b\na,0,3\nc,2,0\n");
    EXPECT_EQ(errorOf(path), path + ": line 3: column condition: unknown condition 'c' (not in the header: a,b)");
}

TEST(Responses, UnknownConditionAgainstTheGivenOrder) {
    const std::string path = writeText("unknown-long.csv", kPwcmpHeader + "o1,s,a,b,1\no1,s,a,x,0\n");
    DatasetOptions options;
    options.conditionOrder = {"a", "b"};
    EXPECT_EQ(errorOf(path, options),
              path + ": line 3: column condition_B: unknown condition 'x' (not in --conditions a,b)");
}

TEST(Responses, APairWithItself) {
    const std::string path = writeText("self.csv", kPwcmpHeader + "o1,s,a,a,1\n");
    EXPECT_EQ(errorOf(path),
              path + ": line 2: column condition_B: condition 'a' is compared with itself (condition_A = condition_B)");
    const std::string matrix = writeText("self-matrix.csv", "condition,a,b\na,4,3\nb,2,0\n");
    EXPECT_EQ(errorOf(matrix),
              matrix + ": line 2: column a: condition 'a' is compared with itself (diagonal count 4, must be 0)");
}

TEST(Responses, NegativeCounts) {
    const std::string path = writeText("negative.csv", "condition,a,b\na,0,-3\nb,2,0\n");
    EXPECT_EQ(errorOf(path), path + ": line 2: column b: negative count -3");
}

TEST(Responses, EmptyFileAndHeaderOnly) {
    const std::string empty = writeText("empty.csv", "");
    EXPECT_EQ(errorOf(empty), empty + ": empty file (expected a header line and responses)");
    const std::string headerOnly = writeText("header-only.csv", kPwcmpHeader);
    EXPECT_EQ(errorOf(headerOnly), headerOnly + ": no responses after the header line");
}

TEST(Responses, MixedBlocksWhereOneIsRequired) {
    const std::string path = writeText("mixed.csv", kPwcmpHeader + "o1,s1,a,b,1\no1,s2,a,b,0\n");
    DatasetOptions options;
    options.singleBlock = true;
    EXPECT_EQ(errorOf(path, options), path + ": line 3: column scene: block 's2' differs from block 's1' of line 2 "
                                             "(--single-block allows one block per file)");
    EXPECT_EQ(errorOf(path), "") << "several blocks are fine without --single-block";
}

TEST(Responses, WrongColumns) {
    const std::string path = writeText("columns.csv", "observer,scene,condition_A,condition_B,chosen\no1,s,a,b,1\n");
    EXPECT_EQ(errorOf(path), path + ": line 1: column is_A_selected: missing column; expected the columns "
                                    "observer,scene,condition_A,condition_B,is_A_selected (scene optional; --columns "
                                    "maps other names), a skinlab export or a count matrix header "
                                    "'condition,<names>'");
    const std::string missing =
        writeText("missing.csv", "observer,scene,condition_A,condition_B,is_A_selected,A_on_left,trial_kind,"
                                 "correct\no1,s,a,b,1,1,test,\n");
    EXPECT_EQ(errorOf(missing), missing + ": line 1: column response_ms: missing column; expected the columns "
                                          "observer,scene,condition_A,condition_B,is_A_selected,A_on_left,trial_kind,"
                                          "correct,response_ms");
    const std::string ragged = writeText("ragged.csv", kPwcmpHeader + "o1,s,a,b\n");
    EXPECT_EQ(errorOf(ragged), ragged + ": line 2: has 4 columns, the header has 5");
}

TEST(Responses, BadValues) {
    const std::string path = writeText("value.csv", kPwcmpHeader + "o1,s,a,b,2\n");
    EXPECT_EQ(errorOf(path), path + ": line 2: column is_A_selected: '2' is not 0 or 1");
    const std::string kind = writeText(
        "kind.csv", "observer,scene,condition_A,condition_B,is_A_selected,A_on_left,trial_kind,correct,response_ms\n"
                    "o1,s,a,b,1,1,warmup,,812\n");
    EXPECT_EQ(errorOf(kind),
              kind + ": line 2: column trial_kind: 'warmup' is not one of test, repeat, catch, practice");
}

TEST(Responses, SkinlabCsvGroupsBlocksObserversAndTrialKinds) {
    const std::string path = writeText(
        "good.csv", "scene,observer,condition_A,condition_B,is_A_selected,A_on_left,trial_kind,correct,response_ms\n"
                    "\"builtin:head/mid\",o1,separable,none,1,1,test,,900\n"
                    "\"builtin:head/mid\",o1,none,separable,0,0,repeat,,700\n"
                    "\"builtin:head/mid\",o1,separable,none,1,1,catch,0,500\n"
                    "\"builtin:head/mid\",o2,separable,none,0,1,test,,800\n"
                    "\"builtin:head/mid\",o2,separable,none,1,1,practice,,800\n"
                    "\"builtin:head/far\",o2,separable,none,1,0,test,,650\n");
    const Dataset dataset = buildDataset(readResponses(path), {});
    ASSERT_EQ(dataset.blocks.size(), 2u);
    const BlockData& mid = dataset.blocks[0];
    EXPECT_EQ(mid.name, "builtin:head/mid");
    EXPECT_EQ(mid.conditions, (std::vector<std::string>{"separable", "none"}));
    EXPECT_EQ(mid.observers, (std::vector<std::string>{"o1", "o2"}));
    // separable (index 0) beat none twice (o1, test and repeat) and lost once (o2).
    EXPECT_EQ(mid.countMatrix()(0, 1), 2.0);
    EXPECT_EQ(mid.countMatrix()(1, 0), 1.0);
    EXPECT_EQ(mid.leftChosen[0], 2.0); // o1 chose the left stimulus both times
    EXPECT_EQ(mid.leftChosen[1], 0.0);
    ASSERT_EQ(dataset.attention.size(), 2u);
    EXPECT_EQ(dataset.attention[0].catchTrials, 1);
    EXPECT_EQ(dataset.attention[0].catchFailures, 1);
    EXPECT_EQ(dataset.attention[1].practiceTrials, 1);
    EXPECT_TRUE(dataset.hasSides);
}

TEST(Responses, StudyDatabaseView) {
    const auto path = scratch() / "study.db";
    std::filesystem::remove(path);
    sqlite3* database = nullptr;
    ASSERT_EQ(sqlite3_open(path.string().c_str(), &database), SQLITE_OK);
    // A real SQLite file with a table and the contract-3 VIEW over it (as the experiments module creates).
    const char* schema =
        "CREATE TABLE answers(id INTEGER PRIMARY KEY, who TEXT, block TEXT, a TEXT, b TEXT, chose_a INTEGER, "
        "a_left INTEGER, kind TEXT, ok INTEGER, ms REAL);"
        "INSERT INTO answers(who,block,a,b,chose_a,a_left,kind,ok,ms) VALUES"
        " ('p1','s','x','y',1,1,'test',NULL,900),('p1','s','y','x',1,0,'test',NULL,800),"
        " ('p2','s','x','y',0,1,'test',NULL,700),('p2','s','x','y',1,1,'catch',1,300);"
        "CREATE VIEW responses_long AS SELECT who AS observer, block AS scene, a AS condition_A, b AS condition_B, "
        "chose_a AS is_A_selected, a_left AS A_on_left, kind AS trial_kind, ok AS correct, ms AS response_ms "
        "FROM answers ORDER BY id;";
    ASSERT_EQ(sqlite3_exec(database, schema, nullptr, nullptr, nullptr), SQLITE_OK);
    sqlite3_close(database);
    const ResponseTable table = readResponses(path);
    EXPECT_EQ(table.format, ResponseFormat::StudyDatabase);
    ASSERT_EQ(table.responses.size(), 4u);
    EXPECT_EQ(table.responses[1].conditionA, "y");
    EXPECT_EQ(table.responses[1].aOnLeft, std::optional<bool>(false));
    EXPECT_EQ(table.responses[3].kind, TrialKind::catchTrial);
    const Dataset dataset = buildDataset(table, {});
    EXPECT_EQ(dataset.blocks.front().countMatrix()(1, 0), 2.0); // y beat x twice

    const auto bare = scratch() / "bare.db";
    std::filesystem::remove(bare);
    ASSERT_EQ(sqlite3_open(bare.string().c_str(), &database), SQLITE_OK);
    ASSERT_EQ(sqlite3_exec(database, "CREATE TABLE t(x);", nullptr, nullptr, nullptr), SQLITE_OK);
    sqlite3_close(database);
    EXPECT_EQ(errorOf(bare.string()),
              bare.string() + ": responses_long: cannot read the responses view: no such table: responses_long");
}

TEST(Responses, PwcmpExtraColumnsAreIgnoredAndColumnsCanBeMapped) {
    // pwcmp's own files carry more columns (examples/ex3_tmo_cmp_data.csv: session_id, criterion).
    const std::string path = writeText("pwcmp-extra.csv", "observer,session_id,scene,condition_A,condition_B,"
                                                          "is_A_selected,criterion\nM01,1,window,a,b,1,perceptual\n"
                                                          "M01,1,window,b,a,0,perceptual\n");
    const ResponseTable table = readResponses(path);
    EXPECT_EQ(table.format, ResponseFormat::PwcmpCsv);
    EXPECT_EQ(table.ignoredColumns, (std::vector<std::string>{"session_id", "criterion"}));
    ASSERT_EQ(table.responses.size(), 2u);
    EXPECT_EQ(table.responses[1].block, "window");
    EXPECT_TRUE(table.responses[0].aSelected);
    EXPECT_FALSE(table.responses[1].aSelected);
    // pw_scale_table's own column names (its default selection column is selected_A), no scene column.
    const std::string renamed =
        writeText("pwcmp-renamed.csv", "subject,cond1,cond2,selected_A\ns1,a,b,1\ns1,a,b,0\ns2,b,a,1\n");
    ReadOptions options;
    options.columns = {
        {"observer", "subject"}, {"condition_A", "cond1"}, {"condition_B", "cond2"}, {"is_A_selected", "selected_A"}};
    const ResponseTable mapped = readResponses(renamed, options);
    EXPECT_EQ(mapped.format, ResponseFormat::PwcmpCsv);
    EXPECT_TRUE(mapped.ignoredColumns.empty());
    ASSERT_EQ(mapped.responses.size(), 3u);
    EXPECT_EQ(mapped.responses[2].observer, "s2");
    EXPECT_EQ(mapped.responses[2].conditionA, "b");
    const Dataset dataset = buildDataset(mapped, {});
    ASSERT_EQ(dataset.blocks.size(), 1u);
    EXPECT_EQ(dataset.blocks[0].name, "all");
    options.columns = {{"observer", "participant"}};
    try {
        readResponses(renamed, options);
        ADD_FAILURE() << "a mapped column that is not in the header must be an error";
    } catch (const skinlab::InputError& e) {
        EXPECT_EQ(std::string(e.what()), renamed + ": --columns: column 'participant' (for observer) is not in the "
                                                   "header (subject,cond1,cond2,selected_A)");
    }
}

} // namespace
} // namespace skinlab::analysis::scaling
