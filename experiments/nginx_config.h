#pragma once
// `skinlab study deploy-config`: the nginx site file of experiments/deploy/nginx-site.conf.in, filled in and
// checked (docs/deployment.md).
#include <string>

namespace skinlab::experiments {

struct NginxSiteOptions {
    std::string serverName;     // the public name (certificate's name; study serve --public-host)
    std::string upstream;       // the study server: IP:PORT (loopback recommended)
    std::string certificate;    // absolute path of the certificate chain (PEM)
    std::string key;            // absolute path of its private key (PEM)
    std::string listen = "443"; // PORT (every address, IPv4 and IPv6) or IPv4-ADDRESS:PORT
    int redirectPort = 0;       // > 0: also listen there in plain HTTP and redirect to https://
};

// The filled-in site file. Throws InputError naming the option at fault (a value nginx would misread, a
// certificate or key that is not a readable file).
std::string nginxSiteConfig(const NginxSiteOptions& options);

} // namespace skinlab::experiments
