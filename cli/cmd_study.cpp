// `skinlab study create|serve|simulate|status|export|backup|deploy-config` — the 2AFC experiment runner (docs/experiments.md).
#include "cli/commands.h"
#include "common/error.h"
#include "common/files.h"
#include "experiments/nginx_config.h"
#include "experiments/simulated_observers.h"
#include "experiments/study_plan.h"
#include "experiments/study_backup.h"
#include "experiments/study_creation.h"
#include "experiments/study_export.h"
#include "experiments/study_server.h"
#include "experiments/study_store.h"

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <functional>
#include <pthread.h>
#include <algorithm>
#include <regex>
#include <sys/stat.h>
#include <thread>
#include <unistd.h>
#include <utility>

namespace skinlab::cli {
namespace ex = skinlab::experiments;

namespace {

struct StudyOptions {
    std::string stimuli;
    std::string design;
    std::string output;
    std::vector<std::string> overrides;
    std::string study;
    std::string host = "127.0.0.1";
    int port = 8080;
    int threads = 8;
    int connectionsPerClient = 64;
    double joinsPerMinute = 60;
    std::string publicHost;
    std::vector<std::string> trustedProxies;
    std::string token;
    std::string tokenFile;
    int sessionsPerParticipant = ex::kDefaultSessionsPerParticipant;
    int joinIpv6Prefix = 64;
    std::string url = "http://127.0.0.1:8080";
    int observers = 0;
    std::string truth;
    std::string truthFactor;
    std::vector<int> planObservers;
    int planSimulations = 200;
    double lapse = 0;
    double sideBias = 0;
    int randomObservers = 0;
    int invertedObservers = 0;
    std::uint64_t seed = 1;
    std::string think;
    std::string labelPrefix;
    bool apiOnly = false;
    std::string format;
    bool overwrite = false;
    bool includeSessionIds = false;
    ex::NginxSiteOptions site;
};

void runCreate(const StudyOptions& o) {
    const ex::CreatedStudy created = ex::createStudy(o.stimuli, o.design, o.overrides, o.output);
    const ex::StudyDefinition& d = created.definition;
    std::printf(
        "%s: %zu block(s), %zu stimuli; per participant %d trials (%d practice, %d test, %d repeat, %d catch)\n",
        o.output.c_str(), d.blocks.size(), d.stimuli.size(), created.trialsPerParticipant, d.design.practiceTrials,
        d.testTrialCount(), d.repeatTrialCount(), d.catchTrialCount());
    for (const std::string& block : created.blocksLeftOut) std::printf("not studied: block %s\n", block.c_str());
    std::printf("next: skinlab study serve %s\n", o.output.c_str());
}

// writeFileAtomic(), the file readable by its owner only (the site file says where the TLS key lies; an export
// holds personal data), written piece by piece as `next` produces them ("" = the end).
void writePrivateFileAtomic(const std::string& path, const std::function<std::string()>& next) {
    AtomicOutput out(path);
    const int fd = ::open(out.tempPath().c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
    if (fd < 0) throw InputError(path + ": cannot write output (" + std::strerror(errno) + ")");
    bool written = ::fchmod(fd, 0600) == 0;
    try {
        for (std::string text = next(); written && !text.empty(); text = next())
            for (std::size_t at = 0; written && at < text.size();) {
                const ssize_t n = ::write(fd, text.data() + at, text.size() - at);
                written = n > 0;
                at += written ? static_cast<std::size_t>(n) : 0;
            }
    } catch (...) {
        ::close(fd);
        throw;
    }
    ::close(fd);
    if (!written) throw InputError(path + ": write failed (" + std::strerror(errno) + ")");
    out.commit();
}

void writePrivateFileAtomic(const std::string& path, const std::string& text) {
    bool given = false;
    writePrivateFileAtomic(path, [&] { return std::exchange(given, true) ? std::string() : text; });
}

// The researcher token: --token (visible to every user in `ps`), --token-file, or SKINLAB_RESEARCHER_TOKEN; empty = a
// random one. The bool says whether it came from the researcher (then it is not printed).
std::pair<std::string, bool> researcherToken(const StudyOptions& o) {
    if (!o.token.empty() && !o.tokenFile.empty()) throw InputError("--token and --token-file: give one of them");
    std::string token = o.token, source = "--token";
    if (!o.tokenFile.empty()) {
        token = readFile(o.tokenFile);
        while (!token.empty() && (token.back() == '\n' || token.back() == '\r')) token.pop_back();
        source = o.tokenFile;
    } else if (const char* environment = std::getenv("SKINLAB_RESEARCHER_TOKEN"); token.empty() && environment) {
        token = environment;
        source = "SKINLAB_RESEARCHER_TOKEN";
        if (token.empty()) throw InputError("SKINLAB_RESEARCHER_TOKEN: empty");
    }
    if (token.empty()) {
        if (!o.tokenFile.empty()) throw InputError(o.tokenFile + ": the researcher token file is empty");
        return {"", false};
    }
    ex::checkResearcherToken(token, source); // >= 128 bits (docs/deployment.md)
    return {token, true};
}

void runServe(const StudyOptions& o) {
    // Block SIGINT/SIGTERM in every thread; one thread waits for them and stops the server cleanly.
    sigset_t signals;
    sigemptyset(&signals);
    sigaddset(&signals, SIGINT);
    sigaddset(&signals, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &signals, nullptr);

    ex::StudyStore store(o.study);
    ex::ServerOptions options;
    options.host = o.host;
    options.port = o.port;
    options.threads = o.threads;
    options.connectionsPerClient = o.connectionsPerClient;
    options.joinsPerMinute = o.joinsPerMinute;
    options.joinBurst = o.joinsPerMinute;
    options.publicHost = o.publicHost;
    options.trustedProxies = o.trustedProxies;
    const auto [token, given] = researcherToken(o);
    options.researcherToken = token;
    options.sessionsPerParticipant = o.sessionsPerParticipant;
    options.joinIpv6Prefix = o.joinIpv6Prefix;
    options.stimuliDir = o.stimuli;
    ex::StudyServer server(store, options);
    server.bind();
    std::printf("serving %s on %s\n", o.study.c_str(), server.url().c_str());
    std::printf("participant link: %s  (each visit of the bare link starts a new participant)\n", server.url().c_str());
    // A token the researcher chose stays out of the output (often a log); a random one must be shown once.
    const std::string shown = given ? "TOKEN" : server.researcherToken();
    if (given) std::printf("researcher token: as given (not printed)\n");
    else std::printf("researcher token: %s\n", shown.c_str());
    std::printf("status: curl -H 'Authorization: Bearer %s' %sapi/researcher/status\n", shown.c_str(),
                server.url().c_str());
    std::printf("dashboard: %sresearcher#token=%s\n", server.url().c_str(), shown.c_str());
    std::fflush(stdout);

    std::thread waiter([&] {
        int received = 0;
        sigwait(&signals, &received);
        server.stop();
    });
    server.run();
    // If run() returned for another reason, wake the waiter.
    pthread_kill(waiter.native_handle(), SIGTERM);
    waiter.join();
    std::printf("stopped\n");
}

// --truth FILE.json, --truth predicted (the manifest's predicted JODs) or --truth-factor NAME.
ex::SimulationTruth truthOf(ex::StudyStore& store, const StudyOptions& o, bool predictedByDefault = false) {
    if (!o.truth.empty() && !o.truthFactor.empty()) throw InputError("--truth and --truth-factor: give one of them");
    if (o.truth == "predicted" || (o.truth.empty() && o.truthFactor.empty() && predictedByDefault))
        return ex::truthFromPredictions(store);
    if (!o.truth.empty()) return ex::readTruthJson(o.truth);
    if (!o.truthFactor.empty()) return ex::truthFromFactor(store, o.truthFactor);
    return {};
}

void runPlan(const StudyOptions& o) {
    ex::StudyStore store(o.study, ex::StudyAccess::readOnly); // also on a read-only mount
    const ex::SimulationTruth truth = truthOf(store, o, true);
    ex::PlanOptions options;
    options.simulations = o.planSimulations;
    options.seed = o.seed;
    if (!o.planObservers.empty()) options.observerCounts = o.planObservers;
    std::sort(options.observerCounts.begin(), options.observerCounts.end());
    std::fputs(ex::planText(ex::planStudy(store.definition(), truth, options)).c_str(), stdout);
}

void runSimulate(const StudyOptions& o) {
    ex::StudyStore store(o.study, ex::StudyAccess::readOnly); // also on a read-only mount
    ex::SimulationOptions options;
    std::smatch m;
    static const std::regex urlPattern(R"(http://([A-Za-z0-9.\-]+|\[[0-9a-fA-F:]+\]):(\d{1,5})/?)");
    if (!std::regex_match(o.url, m, urlPattern)) throw InputError("--url: \"" + o.url + "\" is not http://HOST:PORT");
    options.host = m[1].str();
    options.port = std::stoi(m[2].str());
    options.observers = o.observers;
    if (!o.truth.empty() && !o.truthFactor.empty()) throw InputError("--truth and --truth-factor: give one of them");
    options.truth = truthOf(store, o);
    options.lapseRate = o.lapse;
    options.sideBias = o.sideBias;
    options.randomObservers = o.randomObservers;
    options.invertedObservers = o.invertedObservers;
    options.seed = o.seed;
    options.labelPrefix = o.labelPrefix;
    options.browserLike = !o.apiOnly;
    if (!o.think.empty()) {
        static const std::regex thinkPattern(R"((\d+(?:\.\d+)?)(?::(\d+(?:\.\d+)?))?)");
        if (!std::regex_match(o.think, m, thinkPattern))
            throw InputError("--think-ms: \"" + o.think + "\" is not MS or MIN:MAX");
        options.thinkMinMs = std::stod(m[1].str());
        options.thinkMaxMs = m[2].matched ? std::stod(m[2].str()) : options.thinkMinMs;
        if (options.thinkMaxMs < options.thinkMinMs) throw InputError("--think-ms: MAX is below MIN");
    }
    const ex::SimulationReport report = ex::simulateObservers(store, options);
    for (const ex::ObserverResult& r : report.observers)
        if (!r.failure.empty()) std::printf("%s: stopped: %s\n", r.label.c_str(), r.failure.c_str());
    std::printf("%d/%d observers completed, %zu responses acknowledged, %d rejected, %d re-sends, %.1f s\n",
                report.completed(), o.observers, report.acknowledged(), report.rejected(), report.transportRetries(),
                report.wallSeconds);
    if (report.latenciesMs.empty()) std::printf("response latency: no response was acknowledged\n");
    else
        std::printf("response latency: p50 %.2f ms, p99 %.2f ms\n", report.latencyPercentile(50),
                    report.latencyPercentile(99));
    if (report.completed() != o.observers) throw RuntimeError("not every simulated observer completed the study");
}

void runStatus(const StudyOptions& o) {
    ex::StudyStore store(o.study, ex::StudyAccess::readOnly); // also on a read-only mount
    if (o.format == "json") std::printf("%s\n", ex::statusJson(store).dump(2).c_str());
    else std::printf("%s", ex::statusText(store).c_str());
}

void runBackup(const StudyOptions& o) {
    const ex::BackupSummary summary = ex::backupStudy(o.study, o.output, o.overwrite);
    std::printf("%s: %lld participants, %lld responses, %ju bytes\n", o.output.c_str(),
                static_cast<long long>(summary.participants), static_cast<long long>(summary.responses), summary.bytes);
}

void runDeployConfig(const StudyOptions& o) {
    const std::string text = ex::nginxSiteConfig(o.site);
    if (o.output.empty() || o.output == "-") std::fwrite(text.data(), 1, text.size(), stdout);
    else writePrivateFileAtomic(o.output, text);
}

void runExport(const StudyOptions& o) {
    ex::StudyStore store(o.study, ex::StudyAccess::readOnly); // also on a read-only mount
    // Streamed from a snapshot (experiments/study_export.h); a file is readable by its owner only.
    ex::ResponseExport exporter(store, o.format, {o.includeSessionIds});
    if (!o.output.empty() && o.output != "-") return writePrivateFileAtomic(o.output, [&] { return exporter.next(); });
    for (std::string piece = exporter.next(); !piece.empty(); piece = exporter.next())
        if (std::fwrite(piece.data(), 1, piece.size(), stdout) != piece.size())
            throw InputError("standard output: write failed (" + std::string(std::strerror(errno)) + ")");
}

// `skinlab study create`: its options and what it runs.
void addCreate(CLI::App& study, const std::shared_ptr<StudyOptions>& options) {
    CLI::App* create = study.add_subcommand("create", "Create study.db from a stimulus folder and a design file");
    create->add_option("--stimuli", options->stimuli, "Stimulus folder holding manifest.json")->required();
    create->add_option("--design", options->design, "Design file (TOML)")->required();
    create->add_option("-o,--output", options->output, "Study file to create (never overwritten)")->required();
    create->add_option("--set", options->overrides, "Override a design key: key=value (repeatable)");
    create->callback([options] { runCreate(*options); });
}

// `skinlab study serve`: its options and what it runs.
void addServe(CLI::App& study, const std::shared_ptr<StudyOptions>& options) {
    CLI::App* serve = study.add_subcommand("serve", "Serve the participant page and API");
    serve->add_option("study", options->study, "study.db")->required();
    serve->add_option("--host", options->host, "Address to bind (default loopback only)")->capture_default_str();
    serve->add_option("--port", options->port, "Port (0 = any free port)")
        ->capture_default_str()
        ->check(CLI::Range(0, 65535));
    serve->add_option("--threads", options->threads, "Worker threads running the requests (connections need none)")
        ->capture_default_str()
        ->check(CLI::Range(2, 1024));
    serve->add_option("--public-host", options->publicHost,
                      "Name the server is reached by (checked against the Host header; default: its address only)");
    serve
        ->add_option("--max-connections-per-client", options->connectionsPerClient,
                     "Open connections allowed per client network (an IPv4 address, an IPv6 --join-ipv6-prefix)")
        ->capture_default_str()
        ->check(CLI::Range(1, 100000));
    serve
        ->add_option("--joins-per-minute", options->joinsPerMinute,
                     "New participants per client address per minute (also the burst)")
        ->capture_default_str()
        ->check(CLI::Range(1.0, 1e6));
    serve->add_option("--trusted-proxy", options->trustedProxies,
                      "Address of a reverse proxy whose X-Forwarded-For is believed (repeatable; default with "
                      "--public-host: 127.0.0.1 and ::1)");
    serve->add_option("--token", options->token,
                      "Researcher token (visible in `ps`: prefer --token-file or SKINLAB_RESEARCHER_TOKEN; default: "
                      "random, printed at start)");
    serve->add_option("--token-file", options->tokenFile, "File holding the researcher token (its first line)");
    serve
        ->add_option("--sessions-per-participant", options->sessionsPerParticipant,
                     "Sessions (page loads) allowed per participant")
        ->capture_default_str()
        ->check(CLI::Range(1, 100000));
    serve
        ->add_option("--join-ipv6-prefix", options->joinIpv6Prefix,
                     "IPv6 clients share the join allowance and the connection cap per this prefix length")
        ->capture_default_str()
        ->check(CLI::Range(32, 128));
    serve->add_option("--stimuli", options->stimuli, "Stimulus folder, if it moved since `study create`");
    serve->callback([options] { runServe(*options); });
}

// `skinlab study simulate`: its options and what it runs.
void addSimulate(CLI::App& study, const std::shared_ptr<StudyOptions>& options) {
    CLI::App* simulate = study.add_subcommand("simulate", "Run simulated Thurstone observers through the server");
    simulate->add_option("study", options->study, "study.db (the one the server serves)")->required();
    simulate->add_option("--observers", options->observers, "Number of simultaneous observers")
        ->required()
        ->check(CLI::Range(1, 5000));
    simulate->add_option("--truth", options->truth,
                         "True scores in JOD: \"predicted\" (each stimulus's predicted JOD in the manifest), or a JSON "
                         "file {\"cond\": q} or {\"block\": {\"cond\": q}}");
    simulate->add_option("--truth-factor", options->truthFactor, "Numeric manifest factor holding the true score");
    simulate->add_option("--url", options->url, "Server URL")->capture_default_str();
    simulate->add_option("--lapse", options->lapse, "Probability of a random answer")->check(CLI::Range(0.0, 1.0));
    simulate->add_option("--side-bias", options->sideBias, "JOD added to the left image")
        ->check(CLI::Range(-10.0, 10.0));
    simulate->add_option("--random", options->randomObservers, "Observers answering at random")
        ->check(CLI::Range(0, 5000));
    simulate->add_option("--inverted", options->invertedObservers, "Observers with inverted scores")
        ->check(CLI::Range(0, 5000));
    simulate->add_option("--seed", options->seed, "Seed of the simulated answers")->capture_default_str();
    simulate->add_option("--think-ms", options->think, "Pause before each answer: MS or MIN:MAX");
    simulate->add_option("--label-prefix", options->labelPrefix,
                         "Observer label prefix (default sim-XXXX); run again with the same prefix to continue");
    simulate->add_flag("--api-only", options->apiOnly,
                       "Only the API calls, each on a new connection (default: like a browser — one kept-alive "
                       "connection, the page, the study and each image once)");
    simulate->callback([options] { runSimulate(*options); });
}

// `skinlab study plan`: its options and what it runs.
void addPlan(CLI::App& study, const std::shared_ptr<StudyOptions>& options) {
    CLI::App* plan = study.add_subcommand(
        "plan", "Observers needed for the predicted differences to come out significant (power by simulation)");
    plan->add_option("study", options->study, "study.db")->required();
    plan->add_option("--truth", options->truth,
                     "True scores: \"predicted\" (default: the manifest's predicted JODs) or a JSON file");
    plan->add_option("--truth-factor", options->truthFactor, "Numeric manifest factor holding the true score");
    plan->add_option("--observers", options->planObservers, "Observer counts to simulate, e.g. 10,20,40")
        ->delimiter(',')
        ->check(CLI::Range(2, 10000));
    plan->add_option("--simulations", options->planSimulations, "Simulated studies per observer count")
        ->capture_default_str()
        ->check(CLI::Range(20, 100000));
    plan->add_option("--seed", options->seed, "Seed of the simulations")->capture_default_str();
    plan->callback([options] { runPlan(*options); });
}

// `skinlab study status`: its options and what it runs.
void addStatus(CLI::App& study, const std::shared_ptr<StudyOptions>& options) {
    CLI::App* status = study.add_subcommand("status", "Per-participant progress and catch-trial accuracy");
    status->add_option("study", options->study, "study.db")->required();
    status->add_option("--format", options->format, "text or json")
        ->check(CLI::IsMember({"text", "json"}))
        ->default_val("text");
    status->callback([options] { runStatus(*options); });
}

// `skinlab study backup`: its options and what it runs.
void addBackup(CLI::App& study, const std::shared_ptr<StudyOptions>& options) {
    CLI::App* backup = study.add_subcommand("backup", "Consistent copy of a study file, also while it is served "
                                                      "(SQLite online backup)");
    backup->add_option("study", options->study, "study.db")->required();
    backup->add_option("output", options->output, "Copy to write (atomically)")->required();
    backup->add_flag("--overwrite", options->overwrite, "Replace an existing copy");
    backup->callback([options] { runBackup(*options); });
}

// `skinlab study deploy-config`: its options and what it runs.
void addDeploy(CLI::App& study, const std::shared_ptr<StudyOptions>& options) {
    CLI::App* deploy = study.add_subcommand("deploy-config", "Write the nginx site file that serves the study over "
                                                             "HTTPS (docs/deployment.md)");
    deploy->add_option("--server-name", options->site.serverName, "Public host name (also: study serve --public-host)")
        ->required();
    deploy->add_option("--upstream", options->site.upstream, "The study server: IP:PORT (e.g. 127.0.0.1:8080)")
        ->required();
    deploy->add_option("--cert", options->site.certificate, "Certificate chain (PEM), absolute path")->required();
    deploy->add_option("--key", options->site.key, "Private key (PEM), absolute path")->required();
    deploy->add_option("--listen", options->site.listen,
                       "HTTPS port (every address), or IPv4-ADDRESS:PORT or [IPv6-ADDRESS]:PORT (repeatable; default "
                       "443)");
    deploy->add_option("--access-log", options->site.accessLog, "nginx access log (absolute path, or off)")
        ->capture_default_str();
    deploy->add_option("--redirect-port", options->site.redirectPort, "Also redirect plain HTTP on this port (0 = no)")
        ->capture_default_str()
        ->check(CLI::Range(0, 65535));
    deploy->add_option("-o,--output", options->output, "Site file to write (default: standard output)");
    deploy->callback([options] { runDeployConfig(*options); });
}

// `skinlab study export`: its options and what it runs.
void addExport(CLI::App& study, const std::shared_ptr<StudyOptions>& options) {
    CLI::App* exportCommand =
        study.add_subcommand("export", "Export responses (skinlab CSV, pwcmp CSV or JSON; docs/experiments.md)");
    exportCommand->add_option("study", options->study, "study.db")->required();
    exportCommand->add_option("--format", options->format, "csv, json or pwcmp")
        ->check(CLI::IsMember({"csv", "json", "pwcmp"}))
        ->default_val("csv");
    exportCommand->add_option("-o,--output", options->output,
                              "Output file, readable by its owner only (default: standard output)");
    exportCommand->add_flag("--include-session-ids", options->includeSessionIds,
                            "Include the platform's session ids (SESSION_ID, assignmentId): they resume an unfinished "
                            "participation");
    exportCommand->callback([options] { runExport(*options); });
}

} // namespace

void registerStudy(CLI::App& app) {
    auto options = std::make_shared<StudyOptions>();
    CLI::App* study = app.add_subcommand("study", "2AFC experiments: create a study, serve it, simulate observers, "
                                                  "monitor and export responses");
    study->require_subcommand(1);
    addCreate(*study, options);
    addServe(*study, options);
    addSimulate(*study, options);
    addPlan(*study, options);
    addStatus(*study, options);
    addBackup(*study, options);
    addDeploy(*study, options);
    addExport(*study, options);
}

} // namespace skinlab::cli
