#pragma once
// `skinlab study deploy-config`: the nginx site file of experiments/deploy/nginx-site.conf.in, filled in and
// checked (docs/deployment.md).
#include <string>
#include <vector>

namespace skinlab::experiments {

struct NginxSiteOptions {
    std::string serverName;  // the public name (certificate's name; study serve --public-host)
    std::string upstream;    // the study server: IP:PORT (loopback recommended)
    std::string certificate; // absolute path of the certificate chain (PEM)
    std::string key;         // absolute path of its private key (PEM)
    // Where to listen for HTTPS, each PORT (every address, IPv4 and IPv6), IPv4-ADDRESS:PORT or [IPv6-ADDRESS]:PORT;
    // empty = 443 on every address.
    std::vector<std::string> listen;
    int redirectPort = 0; // > 0: also listen there (on the same addresses) in plain HTTP and redirect to https://NAME
    std::string accessLog = "/var/log/nginx/access.log"; // absolute path, or "off"; query strings are never logged
};

// The filled-in site file. Throws InputError naming the option at fault (a value nginx would misread, a
// certificate or key that is not a readable file).
std::string nginxSiteConfig(const NginxSiteOptions& options);

} // namespace skinlab::experiments
