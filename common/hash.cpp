#include "common/hash.h"

#include "common/error.h"

#include <fstream>
#include <memory>
#include <openssl/evp.h>

namespace skinlab {
namespace {
struct Digest {
    std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> ctx{EVP_MD_CTX_new(), &EVP_MD_CTX_free};
    Digest() { EVP_DigestInit_ex(ctx.get(), EVP_sha256(), nullptr); }
    void update(const void* p, size_t n) { EVP_DigestUpdate(ctx.get(), p, n); }
    std::string hex() {
        unsigned char md[EVP_MAX_MD_SIZE];
        unsigned int len = 0;
        EVP_DigestFinal_ex(ctx.get(), md, &len);
        static const char* digits = "0123456789abcdef";
        std::string out;
        for (unsigned i = 0; i < len; ++i) {
            out += digits[md[i] >> 4];
            out += digits[md[i] & 15];
        }
        return out;
    }
};
} // namespace

std::string sha256Hex(std::string_view data) {
    Digest d;
    d.update(data.data(), data.size());
    return d.hex();
}

std::string sha256File(const std::filesystem::path& path) {
    std::ifstream f(path, std::ios::binary);
    if (!f) throwInput(path.string(), "", "cannot read file to hash it");
    Digest d;
    char buf[1 << 16];
    while (f) {
        f.read(buf, sizeof buf);
        d.update(buf, static_cast<size_t>(f.gcount()));
    }
    return d.hex();
}

} // namespace skinlab
