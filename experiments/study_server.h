#pragma once
// The study's HTTP server: the participant page (embedded HTML/CSS/JS), the participant API, the study's own
// stimulus images, and researcher endpoints behind a token. API reference and limits: docs/experiments.md.
// Transport: HttpServer (event-driven, Boost.Beast; docs/architecture.md, "Study server: threading model").
//
// Every rejected request is answered with a 4xx status and JSON {"error": "..."} and changes nothing: a
// RequestError carries its status, a refusal of the study file (experiments/study_errors.h) is mapped to one here
// (NotFound 404, Conflict 409, LimitReached 429, InvalidValue 400). Request bodies and answers as JSON:
// experiments/study_json.h.
// Only the stimuli listed in the study are served, by number (/stimuli/<n>.png), from the bytes verified against
// their sha256 when the server started (held in memory); no request path is ever mapped onto the file system.
#include "net/http_server.h"
#include "net/join_limiter.h"
#include "experiments/study_store.h"

#include <chrono>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace skinlab::experiments {

struct ServerOptions {
    std::string host = "127.0.0.1";        // loopback unless the researcher says otherwise
    int port = 8080;                       // 0 = any free port
    int threads = 8;                       // worker threads running the handlers (connections need none)
    int ioThreads = 2;                     // threads holding the connections
    std::string researcherToken;           // empty = a random one; otherwise checkResearcherToken()
    std::filesystem::path stimuliDir;      // empty = the folder recorded at `study create`
    std::size_t maxBodyBytes = 16 * 1024;  // larger request bodies are refused with 413 (chunked too)
    std::size_t maxHeaderBytes = 8 * 1024; // larger request headers are refused with 431
    int connectionsPerClient = 64;         // open connections per client network (more: 429)
    std::string publicHost;                // a name the server is reached by (Host header); empty = its address only
    double joinsPerMinute = 60;            // new participants per client address: sustained rate...
    double joinBurst = 60;                 // ...and burst (more: 429 with Retry-After)
    int joinIpv6Prefix = 64;               // IPv6 clients share a join allowance per /64 (bits kept)
    std::size_t joinTableSize = 100000;    // client networks tracked by the join limit (the fullest evicted first)
    int sessionsPerParticipant = kDefaultSessionsPerParticipant; // sessions per participant (more: 429)
    std::chrono::milliseconds requestTimeout{10000}; // a request must arrive within this once started (else 408)
    // Reverse proxies (IP addresses) whose X-Forwarded-For is believed: a request from one of them counts as coming
    // from the address the proxy forwards (join rate limit, per-client request cap, the stored join address); from
    // any other peer the header is ignored. Empty = loopback (127.0.0.1, ::1) when publicHost is set, none otherwise.
    std::vector<std::string> trustedProxies;
    std::chrono::milliseconds dashboardInterval{5000}; // the dashboard's JOD scale is recomputed at most this often
    // Wrong researcher tokens per client network (as joins: an IPv4 address, an IPv6 /64): a burst, then a rate;
    // beyond, every researcher request from there gets 429 with Retry-After, the token unchecked.
    double wrongTokenBurst = 10;
    double wrongTokensPerMinute = 6;
};

// A researcher token must carry at least 128 bits if it were random: at least 32 characters when it is hexadecimal
// digits only (4 bits each), at least 22 otherwise (base64 and the like: 6 bits each; trailing '=' padding is not
// counted), with at least 8 different characters; printable ASCII without blanks, at most 256 characters. The rule
// counts characters: it cannot tell a random token from a phrase (make one with `openssl rand -hex 16`). InputError
// naming `source` otherwise.
void checkResearcherToken(const std::string& token, const std::string& source);

class StudyDashboard;

class StudyServer {
public:
    // Reads every stimulus image once and checks it against its sha256 (InputError naming the file otherwise);
    // an image that resolves outside the stimulus folder (a link out of the set) is refused too.
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
    int openConnections() const { return http_->openConnections(); }

private:
    struct Stimulus {
        std::shared_ptr<const std::string> bytes; // verified at start; served from memory
        std::string etag;                         // "\"<sha256>\""
    };
    net::HttpResponse handle(const net::HttpRequest& request); // answer() with the headers every response carries
    net::HttpResponse answer(const net::HttpRequest& request);
    // The table of endpoints (method and path → handler); each handler below answers one of them.
    net::HttpResponse route(const net::HttpRequest& request);
    // 401 without the researcher token in Authorization: Bearer (or with it in the URL), 403 with a wrong one (logged
    // with the client's address, never the token), 429 once the client's network sent too many wrong ones.
    void authorizeResearcher(const net::HttpRequest& request);
    net::HttpResponse getStimulus(const net::HttpRequest& request) const;
    net::HttpResponse postJoin(const net::HttpRequest& request);
    net::HttpResponse postSession(const net::HttpRequest& request);
    net::HttpResponse getState(const net::HttpRequest& request);
    net::HttpResponse postResponse(const net::HttpRequest& request);
    net::HttpResponse getExport(const net::HttpRequest& request);
    bool hostAllowed(const std::string& host) const;
    // The client's address: the peer's, or the one a trusted proxy forwards (X-Forwarded-For, rightmost entry).
    std::string clientAddress(const net::HttpRequest& request) const;
    bool trustedProxy(const std::string& peer) const;

    StudyStore& store_;
    ServerOptions options_;
    std::vector<Stimulus> stimuli_;
    std::unique_ptr<net::HttpServer> http_;
    int port_ = 0;
    std::unique_ptr<net::JoinLimiter> joinLimiter_;
    std::unique_ptr<net::JoinLimiter> wrongTokens_; // wrong researcher tokens per client network
    // Requests in progress per forwarded client address (behind a proxy every connection is the proxy's).
    std::mutex inFlightMutex_;
    std::map<std::string, int> inFlight_;
    std::unique_ptr<StudyDashboard> dashboard_;
};

} // namespace skinlab::experiments
