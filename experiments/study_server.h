#pragma once
// The study's HTTP server (cpp-httplib): the participant page (embedded HTML/CSS/JS), the participant API,
// the study's own stimulus images, and researcher endpoints behind a token. API reference: docs/experiments.md.
//
// Every rejected request is answered with a 4xx status and JSON {"error": "..."} and changes nothing.
// Only the stimuli listed in the study are served, by number (/stimuli/<n>.png); no request path is ever mapped
// onto the file system.
#include "experiments/study_store.h"

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace httplib {
class Server;
}

namespace skinlab::experiments {

struct ServerOptions {
    std::string host = "127.0.0.1"; // loopback unless the researcher says otherwise
    int port = 8080;                 // 0 = any free port
    int threads = 64;                // worker threads (each holds one connection while it is open)
    std::string researcherToken;     // empty = a random one
    std::filesystem::path stimuliDir; // empty = the folder recorded at `study create`
    std::size_t maxBodyBytes = 16 * 1024; // larger request bodies are refused with 413
};

class StudyServer {
public:
    // Checks every stimulus image against its sha256 before serving (InputError naming the file otherwise).
    StudyServer(StudyStore& store, ServerOptions options);
    ~StudyServer();

    // Binds the listening socket; returns the port (useful with port 0). Throws InputError when it cannot bind.
    int bind();
    // Serves until stop() (blocking).
    void run();
    void stop();
    bool running() const;

    int port() const { return port_; }
    const std::string& researcherToken() const { return options_.researcherToken; }
    std::string url() const;

private:
    void registerRoutes();

    StudyStore& store_;
    ServerOptions options_;
    std::vector<std::filesystem::path> stimulusFiles_;
    std::unique_ptr<httplib::Server> server_;
    int port_ = 0;
    int listeningSocket_ = -1;
};

} // namespace skinlab::experiments
