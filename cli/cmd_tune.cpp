// `skinlab tune`: a live-tuning page for the SSS methods (tune/, docs/tuning.md): sliders for every key the chosen
// method reads, the image re-rendered as they move, a difference view against the object-space reference, the
// kernel as curves, export to a scene spec and a stimulus-set snippet.
#include "cli/commands.h"
#include "cli/options.h"
#include "common/error.h"
#include "common/files.h"
#include "renderer/renderer.h"
#include "renderer/scene/builtin_scenes.h"
#include "tune/tune_server.h"

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <pthread.h>
#include <random>
#include <thread>
#include <unistd.h>

namespace skinlab::cli {

namespace {

struct TuneCliOptions {
    std::vector<std::string> scenes;
    std::string method;
    std::string host = "127.0.0.1";
    int port = 8090;
    std::string tokenFile;
    std::string assets;
    std::string exportDir = ".";
    std::vector<std::string> stimuli;
    int width = 640;
    int height = 360;
};

std::string randomToken() {
    std::random_device device;
    static const char* alphabet = "abcdefghijklmnopqrstuvwxyz0123456789";
    std::string token;
    for (int i = 0; i < 32; ++i) token += alphabet[device() % 36];
    return token;
}

// --token-file or SKINLAB_TUNE_TOKEN; the bool says whether one was given.
std::pair<std::string, bool> tuneToken(const TuneCliOptions& o) {
    std::string token, source;
    if (!o.tokenFile.empty()) {
        token = readFile(o.tokenFile);
        while (!token.empty() && (token.back() == '\n' || token.back() == '\r')) token.pop_back();
        source = o.tokenFile;
        if (token.empty()) throw InputError(o.tokenFile + ": the token file is empty");
    } else if (const char* environment = std::getenv("SKINLAB_TUNE_TOKEN"); environment) {
        token = environment;
        source = "SKINLAB_TUNE_TOKEN";
        if (token.empty()) throw InputError("SKINLAB_TUNE_TOKEN: empty");
    }
    if (token.empty()) return {"", false};
    if (token.size() > 256) throw InputError(source + ": the token is longer than 256 characters");
    for (char c : token)
        if (c <= ' ' || c > '~') throw InputError(source + ": the token must be printable ASCII without blanks");
    return {token, true};
}

void runTune(TuneCliOptions o) {
    sigset_t signals;
    sigemptyset(&signals);
    sigaddset(&signals, SIGINT);
    sigaddset(&signals, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &signals, nullptr);

    tune::TuneOptions options;
    options.host = o.host;
    options.port = o.port;
    options.method = o.method;
    options.width = o.width;
    options.height = o.height;
    options.assetsDir = o.assets;
    options.exportDir = std::filesystem::absolute(o.exportDir);
    // The scenes given first, then the built-in ones.
    for (const std::string& scene : o.scenes)
        options.scenes.push_back(scene.rfind("builtin:", 0) == 0 ? scene : std::filesystem::absolute(scene).string());
    for (const std::string& name : renderer::builtinSceneNames())
        if (std::find(options.scenes.begin(), options.scenes.end(), "builtin:" + name) == options.scenes.end())
            options.scenes.push_back("builtin:" + name);
    for (const std::string& set : o.stimuli) options.stimulusSets.push_back(std::filesystem::absolute(set));
    // Bad input fails here, before the GL context and the socket: the first scene with the method and size.
    renderer::RenderRequest first;
    first.scene = options.scenes.front();
    if (!o.method.empty()) first.method = o.method;
    first.width = o.width;
    first.height = o.height;
    first.assetsDir = o.assets;
    renderer::resolveScene(first);

    auto [token, given] = tuneToken(o);
    const bool loopback = o.host == "127.0.0.1" || o.host == "::1" || o.host == "localhost";
    if (!loopback && token.empty()) token = randomToken();
    options.token = token;
    options.executable = std::filesystem::read_symlink("/proc/self/exe");
    char pattern[] = "/tmp/skinlab-tune-XXXXXX";
    const char* work = mkdtemp(pattern);
    if (!work) throw RuntimeError("cannot create a work folder under /tmp");
    options.workDir = work;

    int stopped = 0;
    {
        tune::TuneServer server(options);
        server.bind();
        std::printf("tuning on %s\n", server.url().c_str());
        if (!token.empty()) {
            std::printf("token: %s\n", given ? "as given (not printed)" : token.c_str());
            std::printf("page: %s#token=%s\n", server.url().c_str(), given ? "TOKEN" : token.c_str());
        }
        std::printf("exports go to %s\n", options.exportDir.c_str());
        std::fflush(stdout);
        std::thread waiter([&] {
            sigwait(&signals, &stopped);
            server.stop();
        });
        server.run();
        pthread_kill(waiter.native_handle(), SIGTERM);
        waiter.join();
    }
    std::filesystem::remove_all(options.workDir);
    std::printf("stopped\n");
}

} // namespace

void registerTune(CLI::App& app) {
    auto options = std::make_shared<TuneCliOptions>();
    CLI::App* tune = app.add_subcommand(
        "tune", "Live tuning in a browser: sliders for the SSS method's keys, the image re-rendered as they move, "
                "difference to the reference, kernel curves, export to a scene spec");
    tune->add_option("scene", options->scenes,
                     "Scene specs or builtin:NAME to offer (first shown first; default builtin:head; the built-in "
                     "scenes are always offered)");
    tune->add_option("--method", options->method, "SSS method shown first (default: the scene's)");
    tune->add_option("--host", options->host, "Address to bind (default loopback; any other needs a token)")
        ->capture_default_str();
    tune->add_option("--port", options->port, "Port (0: any free one)")
        ->capture_default_str()
        ->check(CLI::Range(0, 65535));
    tune->add_option("--token-file", options->tokenFile,
                     "File holding the token the page and API need (or SKINLAB_TUNE_TOKEN; beyond loopback a random "
                     "one is printed when none is given)");
    addAssetsOption(*tune, options->assets);
    tune->add_option("--export-dir", options->exportDir, "Where the page's export writes (default: here)")
        ->capture_default_str();
    tune->add_option("--stimuli", options->stimuli,
                     "A built stimulus set whose stimuli the page may open (repeatable)");
    tune->add_option("--width", options->width, "Image width the page starts with")
        ->capture_default_str()
        ->check(CLI::Range(16, 4096));
    tune->add_option("--height", options->height, "Image height the page starts with")
        ->capture_default_str()
        ->check(CLI::Range(16, 4096));
    tune->callback([options] {
        TuneCliOptions o = *options;
        if (o.scenes.empty()) o.scenes.push_back("builtin:head");
        runTune(o);
    });
}

} // namespace skinlab::cli
