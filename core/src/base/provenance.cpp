#include "mneedle/base/provenance.h"

#include <openssl/evp.h>

#include <array>
#include <charconv>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <memory>
#include <stdexcept>

#include "mneedle/base/error.h"
#include "mneedle_build_info.h"  // generated at build time (cmake/source_revision.cmake)

namespace mneedle {

std::string tool_version() {
  return MNEEDLE_VERSION;
}

std::string source_revision() {
  return MNEEDLE_SOURCE_REVISION;
}

namespace {

// One digest fed in pieces; OpenSSL's EVP interface is the one its manual recommends.
class Sha256 {
 public:
  Sha256() : ctx_(EVP_MD_CTX_new(), &EVP_MD_CTX_free) {
    if (!ctx_ || EVP_DigestInit_ex(ctx_.get(), EVP_sha256(), nullptr) != 1)
      throw std::runtime_error("SHA-256: OpenSSL could not start a digest");
  }
  void update(const char* data, std::size_t size) {
    if (EVP_DigestUpdate(ctx_.get(), data, size) != 1)
      throw std::runtime_error("SHA-256: OpenSSL could not digest");
  }
  std::string hex() {
    std::array<unsigned char, EVP_MAX_MD_SIZE> digest{};
    unsigned int size = 0;
    if (EVP_DigestFinal_ex(ctx_.get(), digest.data(), &size) != 1)
      throw std::runtime_error("SHA-256: OpenSSL could not finish a digest");
    static constexpr char kHex[] = "0123456789abcdef";
    std::string out;
    for (unsigned int i = 0; i < size; ++i) {
      out += kHex[digest[i] >> 4];
      out += kHex[digest[i] & 0xF];
    }
    return out;
  }

 private:
  std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> ctx_;
};

}  // namespace

std::string sha256_hex(std::string_view bytes) {
  Sha256 sha;
  sha.update(bytes.data(), bytes.size());
  return sha.hex();
}

std::string sha256_of_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": cannot read");
  Sha256 sha;
  std::array<char, 1 << 16> buffer{};
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    sha.update(buffer.data(), static_cast<std::size_t>(in.gcount()));
  }
  if (in.bad()) throw InputError(file.string() + ": cannot read");
  return sha.hex();
}

std::string output_time_utc() {
  std::time_t t = std::time(nullptr);
  if (const char* env = std::getenv("SOURCE_DATE_EPOCH")) {
    const std::string_view text(env);
    std::uint64_t seconds = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), seconds);
    // year 9999 is the last one "YYYY" can write
    if (text.empty() || ec != std::errc() || end != text.data() + text.size() ||
        seconds > 253402300799ULL)
      throw InputError("SOURCE_DATE_EPOCH: '" + std::string(text) +
                       "' is not a whole number of seconds since 1970-01-01 UTC");
    t = static_cast<std::time_t>(seconds);
  }
  std::tm utc{};
  gmtime_r(&t, &utc);
  std::array<char, 32> text{};
  std::strftime(text.data(), text.size(), "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text.data();
}

Provenance start_provenance(std::string command) {
  Provenance p;
  p.version = tool_version();
  p.source_revision = source_revision();
  p.command = std::move(command);
  p.time_utc = output_time_utc();
  return p;
}

}  // namespace mneedle
