#include "study_server_fixture.h"

#include "experiments/sqlite_database.h"
#include "experiments/study_creation.h"

namespace skinlab::experiments::test_support {

RunningStudy::RunningStudy(const std::string& designToml, const StimulusSetSpec& spec,
                           const std::function<void(ServerOptions&)>& configure)
    : folder_("server") {
    writeStimulusSet(folder_.path() / "stimuli", spec);
    const auto design = writeText(folder_.path(), "design.toml", designToml);
    database_ = folder_.path() / "study.db";
    createStudy(folder_.path() / "stimuli", design, {}, database_);
    store_ = std::make_unique<StudyStore>(database_);
    ServerOptions options;
    options.port = 0;
    options.researcherToken = kResearcherToken;
    options.threads = 8;
    if (configure) configure(options);
    server_ = std::make_unique<StudyServer>(*store_, options);
    server_->bind();
    thread_ = std::thread([this] { server_->run(); });
}

RunningStudy::~RunningStudy() {
    server_->stop();
    thread_.join();
}

HttpClient RunningStudy::client() const {
    HttpClient client("127.0.0.1", port());
    client.setTimeout(std::chrono::seconds(30));
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
JsonAnswer toAnswer(HttpAnswer res) {
    JsonAnswer answer;
    answer.status = res.status;
    answer.raw = std::move(res.body);
    answer.contentType = res.header("Content-Type");
    answer.headers = std::move(res.headers);
    try {
        answer.body = nlohmann::json::parse(answer.raw);
    } catch (const nlohmann::json::exception&) {
    }
    return answer;
}
} // namespace

JsonAnswer postJson(HttpClient& client, const std::string& path, const nlohmann::json& body) {
    return toAnswer(client.post(path, body.dump()));
}
JsonAnswer postRaw(HttpClient& client, const std::string& path, const std::string& body, const std::string& type) {
    return toAnswer(client.post(path, body, type));
}
JsonAnswer get(HttpClient& client, const std::string& path, const HttpHeaders& headers) {
    return toAnswer(client.get(path, headers));
}

} // namespace skinlab::experiments::test_support
