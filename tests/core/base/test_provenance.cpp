#include "mneedle/base/provenance.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "mneedle/base/error.h"

namespace {

namespace fs = std::filesystem;

// FIPS 180-2, appendix B.1, and the digest of no bytes: any other digest is not SHA-256.
TEST(Sha256, MatchesThePublishedTestVectors) {
  EXPECT_EQ(mneedle::sha256_hex(""),
            "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(mneedle::sha256_hex("abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
}

TEST(Sha256, OfAFileIsTheDigestOfItsBytesReadInPieces) {
  const fs::path file = fs::temp_directory_path() / ("mneedle_sha_" + std::to_string(::getpid()));
  // larger than one read buffer (64 KiB) so the pieces are joined
  const std::string bytes(200000, 'x');
  std::ofstream(file, std::ios::binary) << bytes;
  EXPECT_EQ(mneedle::sha256_of_file(file), mneedle::sha256_hex(bytes));
  fs::remove(file);
}

TEST(Sha256, AFileThatCannotBeReadIsAnErrorNamingIt) {
  try {
    mneedle::sha256_of_file("/no/such/scene.toml");
    FAIL() << "no error";
  } catch (const mneedle::InputError& e) {
    EXPECT_EQ(std::string(e.what()), "/no/such/scene.toml: cannot read");
  }
}

class SourceDateEpoch : public ::testing::Test {
 protected:
  void TearDown() override { ::unsetenv("SOURCE_DATE_EPOCH"); }
};

TEST_F(SourceDateEpoch, SetGivesThatInstantInUtc) {
  ::setenv("SOURCE_DATE_EPOCH", "0", 1);
  EXPECT_EQ(mneedle::output_time_utc(), "1970-01-01T00:00:00Z");
  ::setenv("SOURCE_DATE_EPOCH", "1700000000", 1);  // date -u -d @1700000000
  EXPECT_EQ(mneedle::output_time_utc(), "2023-11-14T22:13:20Z");
}

TEST_F(SourceDateEpoch, UnsetGivesNowAsIso8601) {
  ::unsetenv("SOURCE_DATE_EPOCH");
  const std::string t = mneedle::output_time_utc();
  ASSERT_EQ(t.size(), 20u) << t;
  EXPECT_EQ(t[4], '-');
  EXPECT_EQ(t[10], 'T');
  EXPECT_EQ(t.back(), 'Z');
  EXPECT_GE(std::stoi(t.substr(0, 4)), 2024);
}

TEST_F(SourceDateEpoch, NotAWholeNumberOfSecondsIsAnErrorNamingIt) {
  for (const char* bad : {"", "-1", "12x", "1.5", "abc", "99999999999999999999"}) {
    ::setenv("SOURCE_DATE_EPOCH", bad, 1);
    try {
      (void)mneedle::output_time_utc();
      FAIL() << "accepted '" << bad << "'";
    } catch (const mneedle::InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("SOURCE_DATE_EPOCH: '", 0), 0u) << e.what();
    }
  }
}

TEST_F(SourceDateEpoch, StartedProvenanceCarriesVersionRevisionAndTime) {
  ::setenv("SOURCE_DATE_EPOCH", "86400", 1);
  const mneedle::Provenance p = mneedle::start_provenance("mneedle simulate a.toml");
  EXPECT_EQ(p.version, mneedle::tool_version());
  EXPECT_FALSE(p.version.empty());
  EXPECT_FALSE(p.source_revision.empty());
  EXPECT_EQ(p.command, "mneedle simulate a.toml");
  EXPECT_EQ(p.time_utc, "1970-01-02T00:00:00Z");
  EXPECT_FALSE(p.seed.has_value());
  EXPECT_TRUE(p.inputs.empty());
}

}  // namespace
