// Unit tests of the study file (no HTTP): default participant labels, what client text is stored, trial
// references, and the round trip of every export format through `analyze scale`'s reader.
#include "analysis/scaling/responses.h"
#include "common/files.h"
#include "common/seeded_random.h"
#include "experiments/sqlite_database.h"
#include "experiments/study_creation.h"
#include "experiments/study_errors.h"
#include "experiments/study_export.h"
#include "experiments/study_store.h"
#include "stimulus_set_fixture.h"
#include "store_answer.h"

#include <functional>
#include <gtest/gtest.h>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string_view>
#include <tuple>

using namespace skinlab::experiments;
using namespace skinlab::experiments::test_support;
using skinlab::SeededRandom;
namespace fs = std::filesystem;
namespace scaling = skinlab::analysis::scaling;

namespace {

const char* kDesign = R"(
title = "Store test"
seed = 11
repetitions = 1
[practice]
trials = 1
[catch]
blank = 1
)";

struct StudyFile {
    TempFolder folder{"store"};
    fs::path database = folder.path() / "study.db";
    std::unique_ptr<StudyStore> store;
    StudyFile() {
        writeStimulusSet(folder.path() / "stimuli");
        createStudy(folder.path() / "stimuli", writeText(folder.path(), "design.toml", kDesign), {}, database);
        store = std::make_unique<StudyStore>(database);
    }
};

ResponseInput answer(const ParticipantRecord& p, std::int64_t session, const TrialRecord& t, const std::string& side) {
    return storeAnswer(p, session, t, side);
}

// What the study file refuses `f` with (nullopt: nothing).
std::optional<Refusal> refusalOf(const std::function<void()>& f) {
    try {
        f();
    } catch (const StudyRefusal& e) {
        return e.reason();
    }
    return std::nullopt;
}

bool wellFormedUtf8(const std::string& s) {
    try {
        (void)nlohmann::json(s).dump();
        return true;
    } catch (const nlohmann::json::exception&) {
        return false;
    }
}

} // namespace

TEST(StudyStore, AnExplicitLabelEqualToALaterDefaultDoesNotLockOutBareJoins) {
    StudyFile study;
    for (int i = 0; i < 5; ++i) EXPECT_EQ(study.store->join("").label, "P00" + std::to_string(i + 1));
    EXPECT_EQ(study.store->join("P007").label, "P007"); // takes index 5
    EXPECT_EQ(study.store->join("P009").label, "P009");
    // Index 6 would be P007 (taken) and index 7 P008; each bare join gets the next free label.
    EXPECT_EQ(study.store->join("").label, "P008");
    EXPECT_EQ(study.store->join("").label, "P010");
    EXPECT_EQ(study.store->join("").label, "P011");
    EXPECT_EQ(refusalOf([&] { study.store->join("P008"); }), Refusal::conflict);
}

TEST(StudyStore, ClientTextIsStoredAsWellFormedUtf8AndExportsNeverFail) {
    StudyFile study;
    const ParticipantRecord p = study.store->join("");
    // Invalid bytes, and a valid 3-byte character cut at the 512-byte limit.
    const std::string invalid = "Mozilla/5.0 \xff\xfe (X11)\x01";
    std::string cut(511, 'a');
    cut += "\xE2\x82\xAC"; // U+20AC, bytes 512..514
    const std::int64_t s1 = study.store->startSession(p.id, invalid, 1280, 800, 1.0);
    const std::int64_t s2 = study.store->startSession(p.id, cut, 1280, 800, 1.0);
    const auto trials = study.store->trials(p.id);
    ResponseInput first = answer(p, s1, trials[0], "left");
    first.userAgent = invalid;
    first.clientTime = "\xc3(";
    EXPECT_EQ(study.store->recordResponse(first), ResponseOutcome::stored);
    ResponseInput second = answer(p, s2, trials[1], "left");
    second.userAgent = cut;
    EXPECT_EQ(study.store->recordResponse(second), ResponseOutcome::stored);

    const auto rows = study.store->responses();
    ASSERT_EQ(rows.size(), 2u);
    EXPECT_TRUE(wellFormedUtf8(rows[0].userAgent)) << rows[0].userAgent;
    EXPECT_EQ(rows[0].userAgent, "Mozilla/5.0 \xEF\xBF\xBD\xEF\xBF\xBD (X11)\xEF\xBF\xBD");
    EXPECT_EQ(rows[1].userAgent, std::string(511, 'a')) << "the cut character is dropped whole";
    EXPECT_TRUE(wellFormedUtf8(rows[0].clientTime));
    {
        SqliteDatabase db(study.database.string(), false);
        SqliteStatement s = db.prepare("SELECT user_agent FROM sessions ORDER BY id");
        while (s.step()) EXPECT_TRUE(wellFormedUtf8(s.text(0))) << s.text(0);
        // A study file written before this rule may hold raw bytes: the JSON export still works.
        db.execute("UPDATE responses SET user_agent = CAST(x'4d6f7aff' AS TEXT)");
    }
    const nlohmann::json exported = nlohmann::json::parse(exportResponses(*study.store, "json"));
    EXPECT_EQ(exported["responses"].size(), 2u);
    EXPECT_EQ(exported["responses"][0]["user_agent"], "Moz\xEF\xBF\xBD");
}

TEST(StudyStore, ValidUtf8KeepsWellFormedTextAndBoundsIt) {
    EXPECT_EQ(validUtf8("plain ascii", 512), "plain ascii");
    EXPECT_EQ(validUtf8("Gr\xC3\xBC\xC3\x9F"
                        "e \xF0\x9F\x98\x80",
                        512),
              "Gr\xC3\xBC\xC3\x9F"
              "e \xF0\x9F\x98\x80");
    EXPECT_EQ(validUtf8("\xC0\xAF", 512), "\xEF\xBF\xBD") << "overlong '/'";
    EXPECT_EQ(validUtf8("\xED\xA0\x80", 512), "\xEF\xBF\xBD") << "surrogate";
    EXPECT_EQ(validUtf8("\xF4\x90\x80\x80", 512), "\xEF\xBF\xBD") << "above U+10FFFF";
    EXPECT_EQ(validUtf8("ab\xF0\x9F\x98", 512), "ab\xEF\xBF\xBD") << "truncated at the end";
    EXPECT_EQ(validUtf8("abc\xF0\x9F\x98\x80", 5), "abc");
    SeededRandom random(5);
    for (int i = 0; i < 2000; ++i) {
        std::string bytes;
        const int n = static_cast<int>(random.unit() * 40);
        for (int k = 0; k < n; ++k) bytes += static_cast<char>(static_cast<int>(random.unit() * 256));
        const std::string out = validUtf8(bytes, 32);
        EXPECT_LE(out.size(), 32u);
        EXPECT_TRUE(wellFormedUtf8(out));
    }
}

TEST(StudyStore, TrialReferencesAreTaggedAndScopedToTheirParticipant) {
    StudyFile study;
    const ParticipantRecord alice = study.store->join("alice");
    const ParticipantRecord bob = study.store->join("bob");
    const std::int64_t aliceSession = study.store->startSession(alice.id, "a", 1, 1, 1.0);
    const std::int64_t bobSession = study.store->startSession(bob.id, "b", 1, 1, 1.0);
    const auto aliceTrials = study.store->trials(alice.id);
    const auto bobTrials = study.store->trials(bob.id);
    const std::string before = exportResponses(*study.store, "csv");
    ResponseInput raw = answer(alice, aliceSession, aliceTrials[0], "left");
    raw.trialId = aliceTrials[0].id; // the row id alone is not a reference
    EXPECT_EQ(refusalOf([&] { study.store->recordResponse(raw); }), Refusal::notFound);
    // Bob's first trial, with Alice's token: whether tagged for Bob or for Alice, it is simply unknown (no 403).
    ResponseInput other = answer(alice, aliceSession, bobTrials[0], "left");
    other.trialId = trialReference(bob.token, bobTrials[0].id);
    EXPECT_EQ(refusalOf([&] { study.store->recordResponse(other); }), Refusal::notFound);
    other.trialId = trialReference(alice.token, bobTrials[0].id);
    EXPECT_EQ(refusalOf([&] { study.store->recordResponse(other); }), Refusal::notFound);
    // Bob's session with Alice's trial: unknown too.
    EXPECT_EQ(refusalOf([&] { study.store->recordResponse(answer(alice, bobSession, aliceTrials[0], "left")); }),
              Refusal::notFound);
    EXPECT_EQ(exportResponses(*study.store, "csv"), before);
    // References fit in a JavaScript number and differ between participants.
    EXPECT_LT(trialReference(alice.token, aliceTrials[0].id), std::int64_t(1) << 53);
    EXPECT_NE(trialReference(alice.token, 7), trialReference(bob.token, 7));
    EXPECT_EQ(study.store->recordResponse(answer(alice, aliceSession, aliceTrials[0], "left")),
              ResponseOutcome::stored);
}

// Property: whatever `study export` writes, in any format, `analyze scale`'s reader reads back the same responses,
// whatever the block, condition and observer names hold (commas, quotes, line breaks, spaces, non-ASCII).
TEST(StudyStore, EveryExportFormatReadsBackToTheSameCounts) {
    const std::vector<std::string> alphabet = {"a", "B",  "7",        ",", "\"", "\n", "\r\n",
                                               " ", "\t", "\xC3\xA9", "'", ";",  "-",  "\xE2\x82\xAC"};
    for (std::uint64_t seed = 1; seed <= 12; ++seed) {
        SCOPED_TRACE("seed " + std::to_string(seed));
        StudyFile study;
        SeededRandom random(seed);
        auto randomName = [&](const std::string& base) {
            std::string name;
            const int n = 1 + static_cast<int>(random.unit() * 8);
            for (int k = 0; k < n; ++k)
                name += alphabet[static_cast<std::size_t>(random.unit() * alphabet.size()) % alphabet.size()];
            // Keep names distinct and not only blanks: the reader trims unquoted blanks, as CSV readers do.
            return (random.coin() ? name + base : base + name);
        };
        for (int i = 0; i < 3; ++i) {
            const ParticipantRecord p = study.store->join("");
            const std::int64_t session = study.store->startSession(p.id, "ua", 1, 1, 1.0);
            for (const TrialRecord& t : study.store->trials(p.id))
                study.store->recordResponse(answer(p, session, t, random.coin() ? "left" : "right"));
        }
        {
            // Rename blocks, conditions and observers with hostile characters (the design allows any text).
            SqliteDatabase db(study.database.string(), false);
            std::map<std::string, std::string> names;
            for (const char* column : {"block", "condition_a", "condition_b"}) {
                SqliteStatement s = db.prepare(std::string("SELECT DISTINCT ") + column + " FROM trials");
                while (s.step())
                    if (!names.count(s.text(0))) names[s.text(0)] = randomName("x" + std::to_string(names.size()));
            }
            for (const auto& [from, to] : names)
                for (const char* column : {"block", "condition_a", "condition_b"}) {
                    SqliteStatement u =
                        db.prepare(std::string("UPDATE trials SET ") + column + " = ? WHERE " + column + " = ?");
                    u.bind(1, to).bind(2, from);
                    u.run();
                }
            SqliteStatement s = db.prepare("SELECT id FROM participants");
            std::vector<std::int64_t> ids;
            while (s.step()) ids.push_back(s.integer(0));
            for (std::int64_t id : ids) {
                SqliteStatement u = db.prepare("UPDATE participants SET label = ? WHERE id = ?");
                u.bind(1, randomName("o" + std::to_string(id))).bind(2, id);
                u.run();
            }
        }
        using Key = std::tuple<std::string, std::string, std::string, std::string, bool, std::string>;
        // The CSV formats keep a label that a spreadsheet would run as a formula (a leading = + - @, tab or carriage
        // return) as text, with an apostrophe before it; the JSON export holds the label as stored.
        auto spreadsheetText = [](const std::string& text) {
            return !text.empty() && std::string_view("=+-@\t\r").find(text.front()) != std::string_view::npos
                       ? "'" + text
                       : text;
        };
        std::map<Key, int> expected, expectedCsv, expectedPwcmp;
        for (const ResponseRow& r : study.store->responses()) {
            ++expected[{r.observer, r.scene, r.conditionA, r.conditionB, r.aSelected, trialKindName(r.kind)}];
            ++expectedCsv[{spreadsheetText(r.observer), r.scene, r.conditionA, r.conditionB, r.aSelected,
                           trialKindName(r.kind)}];
            if (r.kind == TrialKind::test || r.kind == TrialKind::repeat)
                ++expectedPwcmp[{spreadsheetText(r.observer), r.scene, r.conditionA, r.conditionB, r.aSelected,
                                 "test"}];
        }
        for (const std::string format : {"csv", "json", "pwcmp"}) {
            const fs::path file = study.folder.path() / ("responses." + format);
            skinlab::writeFileAtomic(file, exportResponses(*study.store, format));
            const scaling::ResponseTable table = scaling::readResponses(file);
            std::map<Key, int> read;
            for (const scaling::Response& r : table.responses) {
                const std::string kind = format == "pwcmp" ? "test" : scaling::trialKindName(r.kind);
                ++read[{r.observer, r.block, r.conditionA, r.conditionB, r.aSelected, kind}];
            }
            EXPECT_EQ(read, format == "pwcmp" ? expectedPwcmp : format == "csv" ? expectedCsv : expected) << format;
        }
    }
}
