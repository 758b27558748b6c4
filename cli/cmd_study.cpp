// `skinlab study create|serve|simulate|status|export|backup|deploy-config` — the 2AFC experiment runner (docs/experiments.md).
#include "cli/commands.h"
#include "cli/options.h"
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

// Each subcommand's arguments; the library's option structs are bound directly, so their defaults are the
// libraries' (shown by --help).
struct CreateArguments {
    std::string stimuli;
    std::string design;
    std::string output;
    std::vector<std::string> overrides;
};

struct ServeArguments {
    std::string study;
    ex::ServerOptions server; // --host, --port, --threads, ... bound to its fields
    std::string token;
    std::string tokenFile;
};

// --truth FILE.json | predicted, --truth-factor NAME (simulate and plan).
struct TruthArguments {
    std::string truth;
    std::string truthFactor;
};

struct SimulateArguments {
    std::string study;
    ex::SimulationOptions simulation; // --observer-count, --lapse, --seed, ... bound to its fields
    TruthArguments truth;
    std::string url = "http://" + ex::SimulationOptions{}.host + ":" + std::to_string(ex::SimulationOptions{}.port);
    std::string think;
    bool apiOnly = false;
    std::string observersList; // --observers: a list of counts elsewhere; here only a clear error
};

struct PlanArguments {
    std::string study;
    ex::PlanOptions plan; // --observers, --simulations, --seed
    TruthArguments truth;
};

struct StudyFileArguments {
    std::string study;
    std::string output;
    std::string format;
    bool overwrite = false;
    bool includeSessionIds = false;
};

struct DeployArguments {
    ex::NginxSiteOptions site;
    std::string output;
};

void runCreate(const CreateArguments& o) {
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
std::pair<std::string, bool> researcherToken(const ServeArguments& o) {
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

void runServe(const ServeArguments& o) {
    // Block SIGINT/SIGTERM in every thread; one thread waits for them and stops the server cleanly.
    sigset_t signals;
    sigemptyset(&signals);
    sigaddset(&signals, SIGINT);
    sigaddset(&signals, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &signals, nullptr);

    ex::StudyStore store(o.study);
    ex::ServerOptions options = o.server;
    options.joinBurst = options.joinsPerMinute;
    const auto [token, given] = researcherToken(o);
    options.researcherToken = token;
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
ex::SimulationTruth truthOf(ex::StudyStore& store, const TruthArguments& o, bool predictedByDefault = false) {
    if (!o.truth.empty() && !o.truthFactor.empty()) throw InputError("--truth and --truth-factor: give one of them");
    if (o.truth == "predicted" || (o.truth.empty() && o.truthFactor.empty() && predictedByDefault))
        return ex::truthFromPredictions(store);
    if (!o.truth.empty()) return ex::readTruthJson(o.truth);
    if (!o.truthFactor.empty()) return ex::truthFromFactor(store, o.truthFactor);
    return {};
}

void runPlan(const PlanArguments& o) {
    ex::StudyStore store(o.study, ex::StudyAccess::readOnly); // also on a read-only mount
    const ex::SimulationTruth truth = truthOf(store, o.truth, true);
    ex::PlanOptions options = o.plan;
    std::sort(options.observerCounts.begin(), options.observerCounts.end());
    std::fputs(ex::planText(ex::planStudy(store.definition(), truth, options)).c_str(), stdout);
}

void runSimulate(const SimulateArguments& o) {
    if (!o.observersList.empty())
        throw InputError("--observers: \"" + o.observersList +
                         "\": study simulate takes the number of observers as --observer-count N (--observers is a "
                         "list of observer counts, in study plan and analyze validate)");
    ex::StudyStore store(o.study, ex::StudyAccess::readOnly); // also on a read-only mount
    ex::SimulationOptions options = o.simulation;
    std::smatch m;
    static const std::regex urlPattern(R"(http://([A-Za-z0-9.\-]+|\[[0-9a-fA-F:]+\]):(\d{1,5})/?)");
    if (!std::regex_match(o.url, m, urlPattern)) throw InputError("--url: \"" + o.url + "\" is not http://HOST:PORT");
    options.host = m[1].str();
    options.port = std::stoi(m[2].str());
    if (!o.truth.truth.empty() && !o.truth.truthFactor.empty())
        throw InputError("--truth and --truth-factor: give one of them");
    options.truth = truthOf(store, o.truth);
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
                report.completed(), options.observers, report.acknowledged(), report.rejected(),
                report.transportRetries(), report.wallSeconds);
    if (report.latenciesMs.empty()) std::printf("response latency: no response was acknowledged\n");
    else
        std::printf("response latency: p50 %.2f ms, p99 %.2f ms\n", report.latencyPercentile(50),
                    report.latencyPercentile(99));
    if (report.completed() != options.observers) throw RuntimeError("not every simulated observer completed the study");
}

void runStatus(const StudyFileArguments& o) {
    ex::StudyStore store(o.study, ex::StudyAccess::readOnly); // also on a read-only mount
    if (o.format == "json") std::printf("%s\n", ex::statusJson(store).dump(2).c_str());
    else std::printf("%s", ex::statusText(store).c_str());
}

void runBackup(const StudyFileArguments& o) {
    const ex::BackupSummary summary = ex::backupStudy(o.study, o.output, o.overwrite);
    std::printf("%s: %lld participants, %lld responses, %ju bytes\n", o.output.c_str(),
                static_cast<long long>(summary.participants), static_cast<long long>(summary.responses), summary.bytes);
}

void runDeployConfig(const DeployArguments& o) {
    const std::string text = ex::nginxSiteConfig(o.site);
    if (o.output.empty() || o.output == "-") std::fwrite(text.data(), 1, text.size(), stdout);
    else writePrivateFileAtomic(o.output, text);
}

void runExport(const StudyFileArguments& o) {
    ex::StudyStore store(o.study, ex::StudyAccess::readOnly); // also on a read-only mount
    // Streamed from a snapshot (experiments/study_export.h); a file is readable by its owner only.
    ex::ResponseExport exporter(store, o.format, {o.includeSessionIds});
    if (!o.output.empty() && o.output != "-") return writePrivateFileAtomic(o.output, [&] { return exporter.next(); });
    for (std::string piece = exporter.next(); !piece.empty(); piece = exporter.next())
        if (std::fwrite(piece.data(), 1, piece.size(), stdout) != piece.size())
            throw InputError("standard output: write failed (" + std::string(std::strerror(errno)) + ")");
}

// `skinlab study create`: its options and what it runs.
void addCreate(CLI::App& study) {
    auto a = std::make_shared<CreateArguments>();
    CLI::App* create = study.add_subcommand("create", "Create study.db from a stimulus folder and a design file");
    create->add_option("--stimuli", a->stimuli, "Stimulus folder holding manifest.json")->required();
    create->add_option("--design", a->design, "Design file (TOML)")->required();
    create->add_option("-o,--output", a->output, "Study file to create (never overwritten)")->required();
    addOverridesOption(*create, a->overrides, "design key");
    create->callback([a] { runCreate(*a); });
}

// `skinlab study serve`: its options (ex::ServerOptions' fields) and what it runs.
void addServe(CLI::App& study) {
    auto a = std::make_shared<ServeArguments>();
    ex::ServerOptions& o = a->server;
    CLI::App* serve = study.add_subcommand("serve", "Serve the participant page and API");
    serve->add_option("study", a->study, "study.db")->required();
    serve->add_option("--host", o.host, "Address to bind (default loopback only)")->capture_default_str();
    serve->add_option("--port", o.port, "Port (0 = any free port)")->capture_default_str()->check(CLI::Range(0, 65535));
    serve->add_option("--threads", o.threads, "Worker threads running the requests (connections need none)")
        ->capture_default_str()
        ->check(CLI::Range(2, 1024));
    serve->add_option("--public-host", o.publicHost,
                      "Name the server is reached by (checked against the Host header; default: its address only)");
    serve
        ->add_option("--max-connections-per-client", o.connectionsPerClient,
                     "Open connections allowed per client network (an IPv4 address, an IPv6 --join-ipv6-prefix)")
        ->capture_default_str()
        ->check(CLI::Range(1, 100000));
    serve
        ->add_option("--joins-per-minute", o.joinsPerMinute,
                     "New participants per client address per minute (also the burst)")
        ->capture_default_str()
        ->check(CLI::Range(1.0, 1e6));
    serve->add_option("--trusted-proxy", o.trustedProxies,
                      "Address of a reverse proxy whose X-Forwarded-For is believed (repeatable; default with "
                      "--public-host: 127.0.0.1 and ::1)");
    serve->add_option("--token", a->token,
                      "Researcher token (visible in `ps`: prefer --token-file or SKINLAB_RESEARCHER_TOKEN; default: "
                      "random, printed at start)");
    serve->add_option("--token-file", a->tokenFile, "File holding the researcher token (its first line)");
    serve
        ->add_option("--sessions-per-participant", o.sessionsPerParticipant,
                     "Sessions (page loads) allowed per participant")
        ->capture_default_str()
        ->check(CLI::Range(1, 100000));
    serve
        ->add_option("--join-ipv6-prefix", o.joinIpv6Prefix,
                     "IPv6 clients share the join allowance and the connection cap per this prefix length")
        ->capture_default_str()
        ->check(CLI::Range(32, 128));
    serve->add_option("--stimuli", o.stimuliDir, "Stimulus folder, if it moved since `study create`");
    serve->callback([a] { runServe(*a); });
}

// --truth and --truth-factor (simulate and plan).
void addTruthOptions(CLI::App& command, TruthArguments& truth, const std::string& truthHelp) {
    command.add_option("--truth", truth.truth, truthHelp);
    command.add_option("--truth-factor", truth.truthFactor, "Numeric manifest factor holding the true score");
}

// `skinlab study simulate`: its options (ex::SimulationOptions' fields) and what it runs.
void addSimulate(CLI::App& study) {
    auto a = std::make_shared<SimulateArguments>();
    ex::SimulationOptions& o = a->simulation;
    CLI::App* simulate = study.add_subcommand("simulate", "Run simulated Thurstone observers through the server");
    simulate->add_option("study", a->study, "study.db (the one the server serves)")->required();
    // Required, checked in the callback so that the old spelling `--observers N` gets its own one-line error.
    CLI::Option* count =
        simulate->add_option("--observer-count", o.observers, "Number of simultaneous observers (required)")
            ->check(CLI::Range(1, 5000));
    simulate->add_option("--observers", a->observersList)->group(""); // hidden: the old spelling, an error
    addTruthOptions(*simulate, a->truth,
                    "True scores in JOD: \"predicted\" (each stimulus's predicted JOD in the manifest), or a JSON "
                    "file {\"cond\": q} or {\"block\": {\"cond\": q}}");
    simulate->add_option("--url", a->url, "Server URL")->capture_default_str();
    simulate->add_option("--lapse", o.lapseRate, "Probability of a random answer")->check(CLI::Range(0.0, 1.0));
    simulate->add_option("--side-bias", o.sideBias, "JOD added to the left image")->check(CLI::Range(-10.0, 10.0));
    simulate->add_option("--random", o.randomObservers, "Observers answering at random")->check(CLI::Range(0, 5000));
    simulate->add_option("--inverted", o.invertedObservers, "Observers with inverted scores")
        ->check(CLI::Range(0, 5000));
    simulate->add_option("--seed", o.seed, "Seed of the simulated answers")->capture_default_str();
    simulate->add_option("--think-ms", a->think, "Pause before each answer: MS or MIN:MAX");
    simulate->add_option("--label-prefix", o.labelPrefix,
                         "Observer label prefix (default sim-XXXX); run again with the same prefix to continue");
    simulate->add_flag("--api-only", a->apiOnly,
                       "Only the API calls, each on a new connection (default: like a browser — one kept-alive "
                       "connection, the page, the study and each image once)");
    simulate->callback([a, count] {
        if (count->count() == 0 && a->observersList.empty())
            throw InputError("--observer-count: required (the number of simultaneous observers)");
        runSimulate(*a);
    });
}

// `skinlab study plan`: its options (ex::PlanOptions' fields) and what it runs.
void addPlan(CLI::App& study) {
    auto a = std::make_shared<PlanArguments>();
    CLI::App* plan = study.add_subcommand(
        "plan", "Observers needed for the predicted differences to come out significant (power by simulation)");
    plan->add_option("study", a->study, "study.db")->required();
    addTruthOptions(*plan, a->truth,
                    "True scores: \"predicted\" (default: the manifest's predicted JODs) or a JSON file");
    plan->add_option("--observers", a->plan.observerCounts, "Observer counts to simulate, e.g. 10,20,40")
        ->delimiter(',')
        ->check(CLI::Range(2, 10000));
    plan->add_option("--simulations", a->plan.simulations, "Simulated studies per observer count")
        ->capture_default_str()
        ->check(CLI::Range(20, 100000));
    plan->add_option("--seed", a->plan.seed, "Seed of the simulations")->capture_default_str();
    plan->callback([a] { runPlan(*a); });
}

// `skinlab study status`: its options and what it runs.
void addStatus(CLI::App& study) {
    auto a = std::make_shared<StudyFileArguments>();
    CLI::App* status = study.add_subcommand("status", "Per-participant progress and catch-trial accuracy");
    status->add_option("study", a->study, "study.db")->required();
    status->add_option("--format", a->format, "text or json")
        ->check(CLI::IsMember({"text", "json"}))
        ->default_val("text");
    status->callback([a] { runStatus(*a); });
}

// `skinlab study backup`: its options and what it runs.
void addBackup(CLI::App& study) {
    auto a = std::make_shared<StudyFileArguments>();
    CLI::App* backup = study.add_subcommand("backup", "Consistent copy of a study file, also while it is served "
                                                      "(SQLite online backup)");
    backup->add_option("study", a->study, "study.db")->required();
    backup->add_option("output", a->output, "Copy to write (atomically)")->required();
    backup->add_flag("--overwrite", a->overwrite, "Replace an existing copy");
    backup->callback([a] { runBackup(*a); });
}

// `skinlab study deploy-config`: its options (ex::NginxSiteOptions' fields) and what it runs.
void addDeploy(CLI::App& study) {
    auto a = std::make_shared<DeployArguments>();
    ex::NginxSiteOptions& site = a->site;
    CLI::App* deploy = study.add_subcommand("deploy-config", "Write the nginx site file that serves the study over "
                                                             "HTTPS (docs/deployment.md)");
    deploy->add_option("--server-name", site.serverName, "Public host name (also: study serve --public-host)")
        ->required();
    deploy->add_option("--upstream", site.upstream, "The study server: IP:PORT (e.g. 127.0.0.1:8080)")->required();
    deploy->add_option("--cert", site.certificate, "Certificate chain (PEM), absolute path")->required();
    deploy->add_option("--key", site.key, "Private key (PEM), absolute path")->required();
    deploy->add_option("--listen", site.listen,
                       "HTTPS port (every address), or IPv4-ADDRESS:PORT or [IPv6-ADDRESS]:PORT (repeatable; default "
                       "443)");
    deploy->add_option("--access-log", site.accessLog, "nginx access log (absolute path, or off)")
        ->capture_default_str();
    deploy->add_option("--redirect-port", site.redirectPort, "Also redirect plain HTTP on this port (0 = no)")
        ->capture_default_str()
        ->check(CLI::Range(0, 65535));
    deploy->add_option("-o,--output", a->output, "Site file to write (default: standard output)");
    deploy->callback([a] { runDeployConfig(*a); });
}

// `skinlab study export`: its options and what it runs.
void addExport(CLI::App& study) {
    auto a = std::make_shared<StudyFileArguments>();
    CLI::App* exportCommand =
        study.add_subcommand("export", "Export responses (skinlab CSV, pwcmp CSV or JSON; docs/experiments.md)");
    exportCommand->add_option("study", a->study, "study.db")->required();
    exportCommand->add_option("--format", a->format, "csv, json or pwcmp")
        ->check(CLI::IsMember({"csv", "json", "pwcmp"}))
        ->default_val("csv");
    exportCommand->add_option("-o,--output", a->output,
                              "Output file, readable by its owner only (default: standard output)");
    exportCommand->add_flag("--include-session-ids", a->includeSessionIds,
                            "Include the platform's session ids (SESSION_ID, assignmentId): they resume an unfinished "
                            "participation");
    exportCommand->callback([a] { runExport(*a); });
}

} // namespace

void registerStudy(CLI::App& app) {
    CLI::App* study = app.add_subcommand("study", "2AFC experiments: create a study, serve it, simulate observers, "
                                                  "monitor and export responses");
    study->require_subcommand(1);
    addCreate(*study);
    addServe(*study);
    addSimulate(*study);
    addPlan(*study);
    addStatus(*study);
    addBackup(*study);
    addDeploy(*study);
    addExport(*study);
}

} // namespace skinlab::cli
