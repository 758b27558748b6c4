#include "experiments/study_text.h"

#include "common/hash.h"

#include <random>

namespace skinlab::experiments {

std::string randomHex(std::size_t bytes) {
    std::random_device device; // /dev/urandom on Linux (libstdc++)
    std::string out;
    static const char digits[] = "0123456789abcdef";
    for (std::size_t i = 0; i < bytes; ++i) {
        const unsigned value = device() & 0xFFu;
        out += digits[value >> 4];
        out += digits[value & 15u];
    }
    return out;
}

std::int64_t trialReference(const std::string& token, std::int64_t trialId) {
    // 20 bits of SHA-256(token, id) above the 32-bit row id: below 2^53, so JavaScript numbers carry it exactly.
    const std::string digest = sha256Hex(token + ":" + std::to_string(trialId));
    const std::int64_t tag = static_cast<std::int64_t>(std::stoul(digest.substr(0, 5), nullptr, 16)) | 1;
    return (tag << 32) | (trialId & 0xFFFFFFFFll);
}

std::string validUtf8(std::string_view text, std::size_t maxBytes) {
    // Well-formed UTF-8 (RFC 3629: no overlongs, no surrogates, at most U+10FFFF); every ill-formed byte becomes
    // U+FFFD, and the result is cut before `maxBytes` on a character boundary.
    static const std::string_view replacement = "\xEF\xBF\xBD";
    std::string out;
    std::size_t i = 0;
    auto append = [&](std::string_view piece) {
        if (out.size() + piece.size() > maxBytes) return false;
        out += piece;
        return true;
    };
    while (i < text.size()) {
        const auto b = static_cast<unsigned char>(text[i]);
        std::size_t length = 0;
        unsigned char low = 0x80, high = 0xBF;
        if (b < 0x80) length = 1;
        else if (b >= 0xC2 && b <= 0xDF) length = 2;
        else if (b >= 0xE0 && b <= 0xEF) {
            length = 3;
            if (b == 0xE0) low = 0xA0;
            if (b == 0xED) high = 0x9F;
        } else if (b >= 0xF0 && b <= 0xF4) {
            length = 4;
            if (b == 0xF0) low = 0x90;
            if (b == 0xF4) high = 0x8F;
        }
        bool ok = length > 0 && i + length <= text.size();
        for (std::size_t k = 1; ok && k < length; ++k) {
            const auto c = static_cast<unsigned char>(text[i + k]);
            const unsigned char lo = k == 1 ? low : 0x80, hi = k == 1 ? high : 0xBF;
            ok = c >= lo && c <= hi;
        }
        if (ok && b < 0x20 && b != '\t') ok = false; // control characters have no place in a stored header
        if (!append(ok ? text.substr(i, length) : replacement)) break;
        if (ok) i += length;
        else {
            // Skip the lead byte and any continuation bytes that belonged to it.
            ++i;
            while (i < text.size() && (static_cast<unsigned char>(text[i]) & 0xC0) == 0x80) ++i;
        }
    }
    return out;
}

std::string makeCompletionCode() {
    // Unambiguous characters only (no 0/O, 1/I/L), 8 of them.
    static const char alphabet[] = "ABCDEFGHJKMNPQRSTUVWXYZ23456789";
    const std::string hex = randomHex(8);
    std::string code;
    for (std::size_t i = 0; i < 8; ++i) {
        const unsigned value = static_cast<unsigned>(std::stoul(hex.substr(i * 2, 2), nullptr, 16));
        code += alphabet[value % (sizeof(alphabet) - 1)];
    }
    return code;
}

} // namespace skinlab::experiments
