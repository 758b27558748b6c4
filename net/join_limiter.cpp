#include "net/join_limiter.h"

#include <algorithm>
#include <boost/asio/ip/address.hpp>

namespace skinlab::net {

std::string clientNetwork(const std::string& address, int ipv6PrefixBits) {
    boost::system::error_code ec;
    const auto parsed = boost::asio::ip::make_address(address, ec);
    if (ec) return address;
    if (parsed.is_v4()) return parsed.to_string();
    const auto v6 = parsed.to_v6();
    if (v6.is_v4_mapped()) return boost::asio::ip::make_address_v4(boost::asio::ip::v4_mapped, v6).to_string();
    const int bits = std::clamp(ipv6PrefixBits, 0, 128);
    auto bytes = v6.to_bytes();
    for (int i = 0; i < 16; ++i) {
        const int keep = std::clamp(bits - 8 * i, 0, 8);
        bytes[static_cast<std::size_t>(i)] &= static_cast<unsigned char>(0xFF00u >> keep);
    }
    return boost::asio::ip::address_v6(bytes).to_string() + "/" + std::to_string(bits);
}

JoinLimiter::JoinLimiter(double perMinute, double burst, std::size_t capacity, int ipv6PrefixBits)
    : perSecond_(perMinute / 60.0), burst_(burst), capacity_(std::max<std::size_t>(capacity, 1)),
      prefixBits_(ipv6PrefixBits) {}

std::size_t JoinLimiter::size() const {
    std::lock_guard lock(mutex_);
    return buckets_.size();
}

bool JoinLimiter::available(const std::string& address, double& retryAfterSeconds, Clock::time_point now) const {
    const std::string key = clientNetwork(address, prefixBits_);
    std::lock_guard lock(mutex_);
    const auto it = buckets_.find(key);
    if (it == buckets_.end()) return burst_ >= 1;
    const double elapsed = std::max(0.0, std::chrono::duration<double>(now - it->second.updated).count());
    const double tokens = std::min(burst_, it->second.tokens + perSecond_ * elapsed);
    if (tokens >= 1) return true;
    retryAfterSeconds = perSecond_ > 0 ? (1 - tokens) / perSecond_ : 60;
    return false;
}

bool JoinLimiter::allow(const std::string& address, double& retryAfterSeconds, Clock::time_point now) {
    const std::string key = clientNetwork(address, prefixBits_);
    std::lock_guard lock(mutex_);
    auto it = buckets_.find(key);
    if (it == buckets_.end()) {
        if (buckets_.size() >= capacity_) {
            // Evict the bucket that is (or will soon be) full again: it limits nobody, or the least.
            const auto evict = refilledAt_.begin();
            buckets_.erase(evict->second);
            refilledAt_.erase(evict);
        }
        Bucket fresh;
        fresh.tokens = burst_;
        fresh.updated = now;
        it = buckets_.emplace(key, fresh).first;
        it->second.byRefill = refilledAt_.emplace(now, key);
    }
    Bucket& bucket = it->second;
    const double elapsed = std::max(0.0, std::chrono::duration<double>(now - bucket.updated).count());
    bucket.tokens = std::min(burst_, bucket.tokens + perSecond_ * elapsed);
    bucket.updated = std::max(bucket.updated, now);
    const bool allowed = bucket.tokens >= 1;
    if (allowed) bucket.tokens -= 1;
    else retryAfterSeconds = perSecond_ > 0 ? (1 - bucket.tokens) / perSecond_ : 60;
    // Re-filed by the time it is full again.
    const double toFull = perSecond_ > 0 ? (burst_ - bucket.tokens) / perSecond_ : 1e9;
    refilledAt_.erase(bucket.byRefill);
    bucket.byRefill = refilledAt_.emplace(
        bucket.updated + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(toFull)), key);
    return allowed;
}

} // namespace skinlab::net
