#pragma once
// A real study: fixture stimulus set → study.db → StudyServer on an ephemeral loopback port, in this process.
#include "experiments/study_server.h"
#include "experiments/study_store.h"
#include "stimulus_set_fixture.h"

#include <httplib.h>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

namespace skinlab::experiments::test_support {

inline const char* kResearcherToken = "researcher-secret-0123456789";

class RunningStudy {
public:
    explicit RunningStudy(const std::string& designToml, const StimulusSetSpec& spec = {});
    ~RunningStudy();

    StudyStore& store() { return *store_; }
    int port() const { return server_->port(); }
    const std::filesystem::path& databasePath() const { return database_; }
    httplib::Client client() const;
    // Every row of every table, as text: equal fingerprints mean nothing was stored or changed.
    std::string fingerprint() const;

private:
    TemporaryFolder folder_;
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
};

JsonAnswer postJson(httplib::Client& client, const std::string& path, const nlohmann::json& body);
JsonAnswer postRaw(httplib::Client& client, const std::string& path, const std::string& body, const std::string& type);
JsonAnswer get(httplib::Client& client, const std::string& path, const httplib::Headers& headers = {});

} // namespace skinlab::experiments::test_support
