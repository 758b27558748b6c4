#pragma once
// The study server's limit on joins per client (also used for wrong researcher tokens per client): a token bucket per client network (an IPv4 address, an IPv6 /64 by
// default — one subscriber usually holds a whole /64, so per address it would not limit anyone), in a table of
// bounded size. When the table is full, the bucket closest to refilled is evicted (a full bucket carries no
// information), never the whole table: an address-spraying flood cannot reset the bucket of a client it wants to
// free. Reference: docs/deployment.md ("Limits").
#include <chrono>
#include <cstddef>
#include <map>
#include <mutex>
#include <string>

namespace skinlab::net {

// The bucket key of an address: IPv4 (or IPv4-mapped IPv6) as it is, IPv6 cut to its first `ipv6PrefixBits` bits
// ("2001:db8:1:2::/64"). Anything that is not an IP address is its own key.
std::string clientNetwork(const std::string& address, int ipv6PrefixBits = 64);

class JoinLimiter {
public:
    using Clock = std::chrono::steady_clock;
    // `burst` joins at once, then `perMinute`; at most `capacity` buckets.
    JoinLimiter(double perMinute, double burst, std::size_t capacity = 100000, int ipv6PrefixBits = 64);

    // Takes one join from the client's bucket: true when allowed; otherwise false and the seconds until one is.
    bool allow(const std::string& address, double& retryAfterSeconds, Clock::time_point now = Clock::now());
    // Whether allow() would allow one now, taking nothing: otherwise false and the seconds until it would.
    bool available(const std::string& address, double& retryAfterSeconds, Clock::time_point now = Clock::now()) const;
    std::size_t size() const;

private:
    struct Bucket {
        double tokens = 0;
        Clock::time_point updated;
        std::multimap<Clock::time_point, std::string>::iterator byRefill; // position in refilledAt_
    };
    double perSecond_, burst_;
    std::size_t capacity_;
    int prefixBits_;
    mutable std::mutex mutex_;
    std::map<std::string, Bucket> buckets_;
    // Every bucket by the time it is full again: the first is the one to evict.
    std::multimap<Clock::time_point, std::string> refilledAt_;
};

} // namespace skinlab::net
