#include "study_server_fixture.h"

#include "experiments/sqlite_database.h"
#include "experiments/study_creation.h"

namespace skinlab::experiments::test_support {

RunningStudy::RunningStudy(const std::string& designToml, const StimulusSetSpec& spec) : folder_("server") {
    writeStimulusSet(folder_.path() / "stimuli", spec);
    const auto design = writeText(folder_.path(), "design.toml", designToml);
    database_ = folder_.path() / "study.db";
    createStudy(folder_.path() / "stimuli", design, {}, database_);
    store_ = std::make_unique<StudyStore>(database_);
    ServerOptions options;
    options.port = 0;
    options.researcherToken = kResearcherToken;
    options.threads = 16;
    server_ = std::make_unique<StudyServer>(*store_, options);
    server_->bind();
    thread_ = std::thread([this] { server_->run(); });
}

RunningStudy::~RunningStudy() {
    server_->stop();
    thread_.join();
}

httplib::Client RunningStudy::client() const {
    httplib::Client client("127.0.0.1", port());
    client.set_connection_timeout(5, 0);
    client.set_read_timeout(30, 0);
    return client;
}

std::string RunningStudy::fingerprint() const {
    SqliteDatabase db(database_.string(), false);
    std::string out;
    for (const char* table : {"meta", "stimuli", "participants", "sessions", "trials", "responses"}) {
        SqliteStatement s = db.prepare(std::string("SELECT * FROM ") + table + " ORDER BY 1");
        out += std::string("#") + table + "\n";
        while (s.step()) {
            for (int c = 0; c < s.columnCount(); ++c) out += s.text(c) + "|";
            out += "\n";
        }
    }
    return out;
}

namespace {
JsonAnswer toAnswer(const httplib::Result& res) {
    JsonAnswer answer;
    if (!res) return answer;
    answer.status = res->status;
    answer.raw = res->body;
    answer.contentType = res->get_header_value("Content-Type");
    try {
        answer.body = nlohmann::json::parse(res->body);
    } catch (const nlohmann::json::parse_error&) {
    }
    return answer;
}
} // namespace

JsonAnswer postJson(httplib::Client& client, const std::string& path, const nlohmann::json& body) {
    return toAnswer(client.Post(path, body.dump(), "application/json"));
}
JsonAnswer postRaw(httplib::Client& client, const std::string& path, const std::string& body, const std::string& type) {
    return toAnswer(client.Post(path, body, type));
}
JsonAnswer get(httplib::Client& client, const std::string& path, const httplib::Headers& headers) {
    return toAnswer(client.Get(path, headers));
}

} // namespace skinlab::experiments::test_support
