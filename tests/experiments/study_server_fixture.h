#pragma once
// A real study: fixture stimulus set → study.db → StudyServer on an ephemeral loopback port, in this process.
#include "experiments/study_server.h"
#include "experiments/study_store.h"
#include "stimulus_set_fixture.h"

#include "net/http_client.h"
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

namespace skinlab::experiments::test_support {

// The HTTP client and requests (net/) by their plain names in the tests.
using namespace skinlab::net;

inline const char* kResearcherToken = "researcher-secret-0123456789";

class RunningStudy {
public:
    explicit RunningStudy(const std::string& designToml, const StimulusSetSpec& spec = {},
                          const std::function<void(ServerOptions&)>& configure = {});
    ~RunningStudy();

    StudyStore& store() { return *store_; }
    StudyServer& server() { return *server_; }
    const std::filesystem::path& folder() const { return folder_.path(); }
    int port() const { return server_->port(); }
    const std::filesystem::path& databasePath() const { return database_; }
    HttpClient client() const;
    // Every row of every table, as text: equal fingerprints mean nothing was stored or changed.
    std::string fingerprint() const;

private:
    TempFolder folder_;
    std::filesystem::path database_;
    std::unique_ptr<StudyStore> store_;
    std::unique_ptr<StudyServer> server_;
    std::thread thread_;
};

struct JsonAnswer {
    int status = 0;
    nlohmann::json body;
    std::string raw;
    std::string contentType;
    HttpHeaders headers;
};

JsonAnswer postJson(HttpClient& client, const std::string& path, const nlohmann::json& body);
JsonAnswer postRaw(HttpClient& client, const std::string& path, const std::string& body, const std::string& type);
JsonAnswer get(HttpClient& client, const std::string& path, const HttpHeaders& headers = {});

} // namespace skinlab::experiments::test_support
