#include "experiments/simulated_observers.h"

#include "common/time.h"
#include "experiments/recruitment.h"
#include "formats/stimulus_manifest.h"

#include "common/error.h"
#include "common/files.h"
#include "common/seeded_random.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include "net/http_client.h"
#include "common/hash.h"
#include <limits>
#include <nlohmann/json.hpp>
#include <set>
#include <thread>

namespace skinlab::experiments {

using nlohmann::json;

using net::HttpAnswer;
using net::HttpClient;
using net::HttpHeaders;

namespace {

// Thurstone Case V scale: σ = 1.4826 makes 1 JOD = 75 % preference (pwcmp).
constexpr double kSigma = 1.4826;

struct HttpResult {
    int status = 0; // 0 = no answer (connection refused, reset, timeout)
    json body;
    double milliseconds = 0;
};

class ApiClient {
public:
    ApiClient(const SimulationOptions& options) : client_(options.host, options.port), options_(options) {
        client_.setTimeout(std::chrono::seconds(30));
        client_.setKeepAlive(options.browserLike); // browsers keep their connection open between requests
        client_.setUserAgent("skinlab-simulate");
    }

    // Sends until an HTTP answer arrives (bounded by maxAttempts); counts the re-sends. A 429 (too many joins or
    // connections from this address) is waited out as its Retry-After says.
    HttpResult send(const std::string& method, const std::string& path, const json& body, int& retries,
                    const HttpHeaders& headers = {}) {
        for (int attempt = 0; attempt < options_.maxAttempts; ++attempt) {
            const auto start = std::chrono::steady_clock::now();
            HttpAnswer res = client_.send(method, path, method == "GET" ? "" : body.dump(), headers);
            const double ms =
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
            if (res.status == 429) {
                const int wait = std::clamp(std::atoi(res.header("Retry-After").c_str()), 1, 10);
                std::this_thread::sleep_for(std::chrono::seconds(wait));
                continue;
            }
            if (res.status != 0) {
                HttpResult out;
                out.status = res.status;
                out.milliseconds = ms;
                try {
                    out.body = json::parse(res.body);
                } catch (const json::parse_error&) {
                    out.body = json{{"error", "not JSON"}};
                }
                return out;
            }
            ++retries;
            std::this_thread::sleep_for(std::chrono::milliseconds(options_.retryDelayMs * std::min(attempt + 1, 10)));
        }
        return {};
    }

    // A static resource, as a browser with a cache fetches it: once per participant (bounded retries).
    void fetchOnce(const std::string& path, int& retries) {
        if (!options_.browserLike || !fetched_.insert(path).second) return;
        for (int attempt = 0; attempt < options_.maxAttempts; ++attempt) {
            if (client_.get(path).status != 0) return;
            ++retries;
            std::this_thread::sleep_for(std::chrono::milliseconds(options_.retryDelayMs * std::min(attempt + 1, 10)));
        }
    }

private:
    HttpClient client_;
    const SimulationOptions& options_;
    std::set<std::string> fetched_;
};

double normal(SeededRandom& random) {
    // Box–Muller.
    double u1 = random.unit();
    while (u1 <= 0) u1 = random.unit();
    const double u2 = random.unit();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

std::string observerLabel(const SimulationOptions& options, int index, const std::string& kind) {
    char label[96];
    std::snprintf(label, sizeof label, "%s-%03d%s", options.labelPrefix.c_str(), index + 1,
                  kind == "thurstone" ? "" : ("-" + kind).c_str());
    return label;
}

json joinRequest(const StudyDesign& design, const std::string& label) {
    json join{{"label", label}, {"join_key", simulatedJoinKey(label)}};
    // An online design: the platform's id parameters, as a recruitment link would carry them (derived from the
    // label, so a second run returns the same observers).
    if (const PlatformParameters names = platformParameters(design.recruitment); !names.id.empty()) {
        const std::string hex = skinlab::sha256Hex("skinlab-simulate-id:" + label);
        std::string upper = hex.substr(0, 20);
        for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
        const std::string id = design.recruitment.platform == "prolific" ? hex.substr(0, 24)
                               : design.recruitment.platform == "mturk"  ? "SIM" + upper
                                                                         : "sim" + hex.substr(0, 20);
        join["recruitment"] = {{names.id, id}};
    }
    return join;
}

json sessionRequest(const StudyDesign& design, const json& screen, const std::string& token) {
    json sessionBody = screen;
    // The viewing conditions a desktop browser in full screen reports (and a calibrated card, if asked for).
    sessionBody.update({{"screen_width", 1920},
                        {"screen_height", 1080},
                        {"colour_depth", 24},
                        {"fullscreen", true},
                        {"pointer_fine", true},
                        {"touch_points", 0}});
    if (design.display.calibrate) sessionBody["card_width"] = 323.5;
    sessionBody["token"] = token;
    return sessionBody;
}

// The observer's answer to a trial: a guess at the lapse rate (always, for "random"), the expected answer to a
// catch trial, else the Thurstone model's choice (qualities negated for "inverted").
bool choosesA(const SimulationOptions& options, const std::string& kind, double invert, const PlannedTrial& t,
              SeededRandom& random) {
    bool chooseA;
    if (kind == "random" || random.unit() < options.lapseRate) {
        chooseA = random.coin();
    } else if (t.kind == TrialKind::catchTrial) {
        chooseA = (t.expected == 'A') == (kind != "inverted");
    } else {
        const double qa = invert * options.truth.quality(t.block, t.conditionA);
        const double qb = invert * options.truth.quality(t.block, t.conditionB);
        const double noise = kSigma / std::sqrt(2.0); // ε ~ N(0, σ²/2)
        const double ua = qa + noise * normal(random) + (t.aOnLeft ? options.sideBias : 0.0);
        const double ub = qb + noise * normal(random) + (t.aOnLeft ? 0.0 : options.sideBias);
        chooseA = ua > ub;
    }
    return chooseA;
}

ObserverResult runObserver(StudyStore& store, const SimulationOptions& options, int index, const std::string& kind,
                           std::vector<double>& latencies) {
    ObserverResult result;
    result.kind = kind;
    result.label = observerLabel(options, index, kind);
    SeededRandom random(combineSeed(options.seed, static_cast<std::uint64_t>(index)));
    ApiClient api(options);

    // The page's own sequence: the page and its script and style, the study, then join (the join key follows from
    // the label, so a second run with the same --label-prefix continues these observers instead of failing).
    for (const char* asset : {"/", "/app.js", "/style.css"}) api.fetchOnce(asset, result.transportRetries);
    if (options.browserLike) api.send("GET", "/api/study", json(), result.transportRetries);
    const StudyDesign& design = store.definition().design;
    HttpResult joined = api.send("POST", "/api/join", joinRequest(design, result.label), result.transportRetries);
    if (joined.status != 201 && joined.status != 200) {
        result.failure = "join: " + (joined.status ? joined.body.value("error", std::string("?")) : "no answer");
        return result;
    }
    const std::string token = joined.body["token"].get<std::string>();
    const json screen{{"viewport_width", 1920}, {"viewport_height", 1080}, {"device_pixel_ratio", 1.0}};
    HttpResult state = api.send("POST", "/api/session", sessionRequest(design, screen, token), result.transportRetries);
    if (state.status != 200) {
        result.failure = "session: " + (state.status ? state.body.value("error", std::string("?")) : "no answer");
        return result;
    }
    const std::int64_t session = state.body["session"].get<std::int64_t>();

    // The plan, read from study.db, tells the simulated observer what each trial shows.
    const ParticipantRecord participant = store.participant(token);
    std::map<std::int64_t, std::pair<std::int64_t, PlannedTrial>> plan; // by reference: (row id, trial)
    for (const TrialRecord& t : store.trials(participant.id)) plan[trialReference(token, t.id)] = {t.id, t.plan};
    const double invert = kind == "inverted" ? -1.0 : 1.0;

    // Bounded: every iteration either acknowledges a response or counts a rejection. (An active design stores its
    // plan batch by batch: the length comes from the server's progress.)
    const std::size_t planned = std::max<std::size_t>(
        plan.size(), static_cast<std::size_t>(state.body.value("total", 0) + state.body.value("practice_total", 0)));
    const std::size_t maxSteps = planned * 2 + 10;
    for (std::size_t step = 0; step < maxSteps; ++step) {
        const json& body = state.body;
        if (body.value("completed", false)) {
            result.completed = true;
            result.completionCode = body.value("completion_code", std::string());
            break;
        }
        const std::int64_t trialId = body["trial"]["id"].get<std::int64_t>();
        auto it = plan.find(trialId);
        if (it == plan.end()) { // an active design's next batch, stored since the plan was read
            for (const TrialRecord& t : store.trials(participant.id))
                plan[trialReference(token, t.id)] = {t.id, t.plan};
            it = plan.find(trialId);
        }
        if (it == plan.end()) {
            result.failure = "trial " + std::to_string(trialId) + " is not in this participant's plan";
            break;
        }
        const PlannedTrial& t = it->second.second;
        // Both images (and the reference), each once: the browser's cache keeps them (immutable, ETag).
        for (const char* side : {"left", "right", "reference"}) {
            const json& shown = body["trial"][side];
            if (shown.is_object() && shown.contains("url"))
                api.fetchOnce(shown["url"].get<std::string>(), result.transportRetries);
        }
        const bool chooseA = choosesA(options, kind, invert, t, random);
        const std::string side = chooseA == t.aOnLeft ? "left" : "right";
        if (options.thinkMaxMs > 0) {
            const double ms = options.thinkMinMs + random.unit() * (options.thinkMaxMs - options.thinkMinMs);
            std::this_thread::sleep_for(std::chrono::microseconds(static_cast<long>(ms * 1000)));
        }
        json response = screen;
        response["token"] = token;
        response["trial"] = trialId;
        response["side"] = side;
        response["session"] = session;
        response["response_ms"] = 800.0 + 400.0 * random.unit();
        response["client_time"] = utcTimestamp();
        HttpResult answer = api.send("POST", "/api/response", response, result.transportRetries);
        if (answer.status == 200) {
            result.acknowledged.emplace_back(it->second.first, side);
            ++result.answered;
            latencies.push_back(answer.milliseconds);
            state = std::move(answer);
            continue;
        }
        ++result.rejected;
        if (answer.status == 0) {
            result.failure = "server unreachable";
            break;
        }
        // Re-synchronise with the server's view of this participant.
        state = api.send("GET", "/api/state", json(), result.transportRetries, {{"X-Skinlab-Token", token}});
        if (state.status != 200) {
            result.failure = "state: HTTP " + std::to_string(state.status);
            break;
        }
    }
    return result;
}

} // namespace

std::string simulatedJoinKey(const std::string& label) {
    return "sim-" + skinlab::sha256Hex("skinlab-simulate:" + label).substr(0, 40);
}

double SimulationTruth::quality(const std::string& block, const std::string& condition) const {
    if (auto b = byBlock.find(block); b != byBlock.end()) {
        if (auto c = b->second.find(condition); c != b->second.end()) return c->second;
    }
    if (auto c = byCondition.find(condition); c != byCondition.end()) return c->second;
    if (byCondition.empty() && byBlock.empty()) return 0.0; // no truth given: all conditions equal
    throw InputError(source + ": no score for condition \"" + condition + "\" (block \"" + block + "\")");
}

SimulationTruth readTruthJson(const std::filesystem::path& path) {
    SimulationTruth truth;
    truth.source = path.string();
    json root;
    try {
        root = json::parse(readFile(path));
    } catch (const json::parse_error& e) {
        throw InputError(path.string() + ": not valid JSON: " + e.what());
    }
    if (!root.is_object() || root.empty())
        throw InputError(path.string() + ": expected an object of scores {\"condition\": JOD, ...}");
    for (auto it = root.begin(); it != root.end(); ++it) {
        if (it.value().is_number()) {
            truth.byCondition[it.key()] = it.value().get<double>();
        } else if (it.value().is_object()) {
            for (auto c = it.value().begin(); c != it.value().end(); ++c) {
                if (!c.value().is_number())
                    throw InputError(path.string() + ": " + it.key() + "." + c.key() + ": expected a number");
                truth.byBlock[it.key()][c.key()] = c.value().get<double>();
            }
        } else {
            throw InputError(path.string() + ": " + it.key() + ": expected a number or an object of numbers");
        }
    }
    return truth;
}

namespace {

// Calls f(stimulus, its manifest entry) for every stimulus of the study that shows a condition (not a reference).
template <typename F>
void forEachConditionEntry(StudyStore& store, F f) {
    // The manifest stored in the study, by the one strict reader of contract 2 (formats/stimulus_manifest.h).
    const formats::StimulusManifest manifest =
        formats::parseStimulusManifest(store.meta("manifest_json"), "the study's stored manifest.json");
    std::map<std::string, const formats::ManifestEntry*> byId;
    for (const formats::ManifestEntry& s : manifest.stimuli) byId[s.id] = &s;
    for (const StudyStimulus& s : store.definition().stimuli)
        if (!s.condition.empty()) f(s, *byId.at(s.id));
}

} // namespace

SimulationTruth truthFromPredictions(StudyStore& store) {
    SimulationTruth truth;
    truth.source = "--truth predicted";
    forEachConditionEntry(store, [&](const StudyStimulus& s, const formats::ManifestEntry& entry) {
        // A block's reference shown as a condition is, by definition, indistinguishable from itself.
        if (entry.reference) {
            truth.byBlock[s.block][s.condition] = 10.0;
            return;
        }
        if (!entry.predicted)
            throw InputError("--truth predicted: stimulus \"" + s.id +
                             "\" has no predicted JOD in the manifest (build the set with a [[reference]] so that "
                             "`stimuli build` predicts each stimulus against it)");
        truth.byBlock[s.block][s.condition] = entry.predicted->jod;
    });
    return truth;
}

SimulationTruth truthFromFactor(StudyStore& store, const std::string& factor) {
    SimulationTruth truth;
    truth.source = "--truth-factor " + factor;
    forEachConditionEntry(store, [&](const StudyStimulus& s, const formats::ManifestEntry& entry) {
        if (!entry.factors.contains(factor))
            throw InputError("--truth-factor: stimulus \"" + s.id + "\" has no factor \"" + factor + "\"");
        const json& value = entry.factors.at(factor);
        double q = 0;
        if (value.is_number()) {
            q = value.get<double>();
        } else {
            try {
                std::size_t used = 0;
                const std::string text = value.is_string() ? value.get<std::string>() : value.dump();
                q = std::stod(text, &used);
                if (used != text.size()) throw std::invalid_argument(text);
            } catch (const std::exception&) {
                throw InputError("--truth-factor: stimulus \"" + s.id + "\": factor \"" + factor +
                                 "\" = " + value.dump() + " is not a number");
            }
        }
        truth.byBlock[s.block][s.condition] = q;
    });
    return truth;
}

int SimulationReport::completed() const {
    int n = 0;
    for (const ObserverResult& o : observers) n += o.completed ? 1 : 0;
    return n;
}
int SimulationReport::rejected() const {
    int n = 0;
    for (const ObserverResult& o : observers) n += o.rejected;
    return n;
}
int SimulationReport::transportRetries() const {
    int n = 0;
    for (const ObserverResult& o : observers) n += o.transportRetries;
    return n;
}
std::size_t SimulationReport::acknowledged() const {
    std::size_t n = 0;
    for (const ObserverResult& o : observers) n += o.acknowledged.size();
    return n;
}
double SimulationReport::latencyPercentile(double p) const {
    if (latenciesMs.empty()) return std::numeric_limits<double>::quiet_NaN();
    std::vector<double> sorted = latenciesMs;
    std::sort(sorted.begin(), sorted.end());
    // Nearest-rank percentile.
    const std::size_t rank = static_cast<std::size_t>(std::ceil(p / 100.0 * static_cast<double>(sorted.size())));
    return sorted[std::min(sorted.size() - 1, rank == 0 ? 0 : rank - 1)];
}

SimulationReport simulateObservers(StudyStore& store, const SimulationOptions& optionsIn) {
    SimulationOptions options = optionsIn;
    if (options.observers < 1) throw InputError("--observers: must be at least 1");
    if (options.randomObservers + options.invertedObservers > options.observers)
        throw InputError("--random/--inverted: more special observers than --observers");
    if (options.labelPrefix.empty()) options.labelPrefix = "sim-" + randomHex(2);
    // Every compared condition needs a score before any observer starts.
    for (const StudyBlock& block : store.definition().blocks)
        for (const std::string& condition : block.conditions) (void)options.truth.quality(block.name, condition);
    SimulationReport report;
    report.observers.resize(static_cast<std::size_t>(options.observers));
    std::vector<std::vector<double>> latencies(static_cast<std::size_t>(options.observers));
    const auto start = std::chrono::steady_clock::now();
    std::vector<std::thread> threads;
    for (int i = 0; i < options.observers; ++i) {
        const std::string kind = i < options.randomObservers                               ? "random"
                                 : i < options.randomObservers + options.invertedObservers ? "inverted"
                                                                                           : "thurstone";
        threads.emplace_back([&, i, kind] {
            try {
                report.observers[static_cast<std::size_t>(i)] =
                    runObserver(store, options, i, kind, latencies[static_cast<std::size_t>(i)]);
            } catch (const std::exception& e) {
                report.observers[static_cast<std::size_t>(i)].failure = e.what();
            }
        });
    }
    for (std::thread& t : threads) t.join();
    report.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    for (const auto& l : latencies) report.latenciesMs.insert(report.latenciesMs.end(), l.begin(), l.end());
    return report;
}

} // namespace skinlab::experiments
