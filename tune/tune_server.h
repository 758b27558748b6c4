#pragma once
// `skinlab tune`: the live-tuning page and its JSON API on the project's HTTP server (net/http_server.h).
// Loopback by default; bound to any other address only with a token (Authorization: Bearer TOKEN on every /api/
// request). Requests from other sites are refused: every /api/ request must come from the page's own origin
// (Origin, Sec-Fetch-Site), and every POST must be JSON and carry the page's token, random per start (embedded in
// the page it serves). Paths the page sends are read only inside the offered scenes' folders, the assets folder and
// the stimulus sets. Routes and limits: docs/tuning.md.
#include "net/http_server.h"
#include "tune/tune_engine.h"

#include <filesystem>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace skinlab::tune {

struct TuneOptions {
    std::string host = "127.0.0.1";
    int port = 0;
    std::string token;               // required unless the host is a loopback address
    std::vector<std::string> scenes; // the scenes the page offers; the first is shown first
    std::string method;              // the method shown first (empty: the scene's own)
    int width = 640;                 // the size the page starts with
    int height = 360;
    std::filesystem::path assetsDir;                 // --assets (empty: $SKINLAB_ASSETS)
    std::filesystem::path exportDir;                 // where "export" writes
    std::vector<std::filesystem::path> stimulusSets; // built sets "open" reads (manifest.json)
    std::filesystem::path executable;                // the skinlab binary (background renders)
    std::filesystem::path workDir;                   // background renders' files
};

class TuneServer {
public:
    explicit TuneServer(TuneOptions options); // throws InputError for bad options
    ~TuneServer();
    TuneServer(const TuneServer&) = delete;
    TuneServer& operator=(const TuneServer&) = delete;

    int bind(); // returns the port
    void run(); // blocks until stop()
    void stop();
    std::string url() const;

    // The request handler (public for tests that call it without a socket).
    net::HttpResponse handle(const net::HttpRequest& request);

    // The folders the page's path-valued keys may name (canonical).
    const std::vector<std::filesystem::path>& readableFolders() const { return readable_; }

private:
    net::HttpResponse answer(const net::HttpRequest& request);
    net::HttpResponse page(const std::string& path) const;
    // Every /api/ request: the page's own origin, the token when one is set, and for a POST checkPageRequest().
    void guardApi(const net::HttpRequest& request) const;
    void checkPageRequest(const net::HttpRequest& request) const;
    TuneConfig requestConfig(const nlohmann::json& body) const;
    void checkPathKeys(const TuneConfig& config) const;
    net::HttpResponse reference(const nlohmann::json& body);
    net::HttpResponse exportFiles(const nlohmann::json& body);
    net::HttpResponse job(const net::HttpRequest& request) const;
    net::HttpResponse open(const net::HttpRequest& request) const;
    nlohmann::json schema() const;
    net::HttpResponse render(const nlohmann::json& body);
    nlohmann::json compare(const nlohmann::json& request, const TuneFrame& frame);
    nlohmann::json stimulusList() const;
    nlohmann::json openStimulus(const std::string& id) const;

    TuneOptions options_;
    std::filesystem::path assets_;                // --assets or $SKINLAB_ASSETS
    std::string pageToken_;                       // random per start: the page sends it with every POST
    std::vector<std::filesystem::path> readable_; // see readableFolders()
    int port_ = 0;
    std::unique_ptr<RenderQueue> queue_;
    std::unique_ptr<JobRunner> jobs_;
    std::unique_ptr<net::HttpServer> http_;
    struct PreparedReferences;
    std::unique_ptr<PreparedReferences> references_;
};

// The configuration of a request body: {"scene": S, "overrides": ["key=value", ...]}; the scene must be one of
// `scenes`. Throws RequestError (400) naming the field.
TuneConfig configOf(const nlohmann::json& body, const std::vector<std::string>& scenes);

} // namespace skinlab::tune
