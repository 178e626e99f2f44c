// PLY structure checks run before assimp, which reads past the end of a short binary PLY.
#include "needle/ply_check.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "mneedle/base/error.h"

namespace {

std::string error_of(const std::string& bytes) {
  try {
    mneedle::ply::check_structure("m.ply", bytes);
  } catch (const mneedle::InputError& e) {
    return e.what();
  }
  return "";
}

const std::string kBinaryHeader =
    "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
    "property float y\nproperty float z\nelement face 1\nproperty list uchar int "
    "vertex_indices\nend_header\n";

std::string binary_triangle() {
  std::string data(36, '\0');  // three vertices at the origin: the structure is what matters
  data += '\3';
  for (std::int32_t i : {0, 1, 2}) data.append(reinterpret_cast<const char*>(&i), 4);
  return kBinaryHeader + data;
}

TEST(PlyCheck, CompleteBinaryAndAsciiFilesPass) {
  EXPECT_EQ(error_of(binary_triangle()), "");
  EXPECT_EQ(error_of("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float "
                     "y\nproperty float z\nelement face 1\nproperty list uchar int "
                     "vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),
            "");
}

TEST(PlyCheck, BinaryDataShorterThanItsHeaderSaysIsRefused) {
  // fuzz_mesh's first find: assimp 5.2 read past the buffer on a file like this (SIGSEGV).
  const std::string full = binary_triangle();
  for (std::size_t cut : {full.size() - 1, full.size() - 12, kBinaryHeader.size() + 20}) {
    const std::string message = error_of(full.substr(0, cut));
    EXPECT_NE(message.find("shorter than its header says"), std::string::npos) << cut;
    EXPECT_EQ(message.rfind("m.ply: ", 0), 0u) << message;
  }
}

TEST(PlyCheck, ListLengthBeyondTheDataOrNegativeIsRefused) {
  std::string longer = binary_triangle();
  longer[kBinaryHeader.size() + 36] = '\x7f';  // a face of 127 indices in 12 bytes
  EXPECT_NE(error_of(longer).find("shorter than its header says"), std::string::npos);
  std::string header = kBinaryHeader;
  header.replace(header.find("uchar int"), 9, "char int");
  std::string negative = header + std::string(36, '\0') + '\xff' + std::string(12, '\0');
  EXPECT_NE(error_of(negative).find("negative length"), std::string::npos);
}

TEST(PlyCheck, HeaderWithoutEndOrWithUnknownTypesIsRefused) {
  EXPECT_NE(error_of("ply\nformat binary_little_endian 1.0\nelement vertex 3\n").find("end_header"),
            std::string::npos);
  EXPECT_NE(error_of("ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n1\n")
                .find("unknown type"),
            std::string::npos);
  EXPECT_NE(error_of("ply\nformat xml 1.0\nend_header\n").find("format 'xml'"), std::string::npos);
  EXPECT_NE(error_of("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float w\n"
                     "property float z\nend_header\n0 0\n")
                .find("without a vertex element with x, y and z"),
            std::string::npos);
  EXPECT_NE(error_of("ply\nformat ascii 1.0\nelement vertex 0\nelement vertex 0\nend_header\n")
                .find("element 'vertex' declared twice"),
            std::string::npos);
  EXPECT_NE(error_of("ply\nformat ascii 1.0\nelement vertex 5\nend_header\n")
                .find("has a count but no properties"),
            std::string::npos);
}

TEST(PlyCheck, AsciiCountBeyondItsLinesIsRefusedBeforeAnyoneReservesMemoryForIt) {
  const std::string message = error_of(
      "ply\nformat ascii 1.0\nelement vertex 1000000000000\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n0 0 0\n1 0 0\n");
  EXPECT_NE(message.find("declares 1000000000000 elements but the data has 2 lines"),
            std::string::npos)
      << message;
}

}  // namespace

namespace {

TEST(PlyCheck, AsciiLineShorterOrLongerThanItsPropertiesIsRefusedWithItsLine) {
  // fuzz_mesh's second find: assimp 5.2 aborts on a face line shorter than its list length.
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty "
      "float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const std::string vertices = "0 0 0\n1 0 0\n0 1 0\n";
  EXPECT_NE(error_of(header + vertices + "3 0 1\n")
                .find("line 4 (element 'face' 0): fewer numbers "
                      "than its list length"),
            std::string::npos)
      << error_of(header + vertices + "3 0 1\n");
  EXPECT_NE(error_of(header + vertices + "3 0 1 2 7\n").find("more numbers"), std::string::npos);
  EXPECT_NE(error_of(header + "0 0\n1 0 0\n0 1 0\n3 0 1 2\n").find("fewer numbers than its prop"),
            std::string::npos);
  EXPECT_NE(error_of(header + vertices + "2.5 0 1\n").find("not a whole number"),
            std::string::npos);
  EXPECT_NE(error_of(header + vertices + "1e30 0 1 2\n").find("not a whole number from 0 to"),
            std::string::npos);
}

}  // namespace

namespace {

TEST(PlyCheck, FaceIndexOutsideTheVerticesIsRefusedInBothEncodings) {
  // fuzz_mesh's fourth find: assimp 5.2 aborts on such a binary file.
  std::string binary = binary_triangle();
  binary[binary.size() - 4] = '\3';  // the last index: vertex 3 of 3
  EXPECT_NE(error_of(binary).find("PLY face 0 refers to vertex 3 of 3"), std::string::npos)
      << error_of(binary);
  const std::string ascii =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty "
      "float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 "
      "0\n0 1 0\n3 0 1 -1\n";
  EXPECT_NE(error_of(ascii).find("PLY face 0 refers to vertex -1 of 3"), std::string::npos)
      << error_of(ascii);
}

}  // namespace

namespace {

TEST(PlyCheck, FaceOfFewerThanThreeVerticesIsRefused) {
  // fuzz_mesh's fifth find: assimp 5.2 aborts in its post-processing on a two-vertex face.
  const std::string ascii =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty "
      "float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 "
      "0\n0 1 0\n2 0 1\n";
  EXPECT_NE(error_of(ascii).find("PLY face 0 has 2 vertices (a face needs at least 3)"),
            std::string::npos)
      << error_of(ascii);
}

}  // namespace

namespace {

TEST(PlyCheck, HeaderLineWithAnUnknownKeywordIsRefused) {
  // fuzz_mesh's sixth find: assimp 5.2 did not return on a header with a mangled "element".
  const std::string message = error_of(
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelemXnt face 1\nend_header\n0 0 0\n1 0 0\n0 1 0\n");
  EXPECT_NE(message.find("'elemXnt face 1' is not a PLY header keyword"), std::string::npos)
      << message;
}

}  // namespace

namespace {

TEST(PlyCheck, FaceIndexBeyondAnyIntegerIsRefusedAndPrintedAsWritten) {
  // fuzz_mesh's eighth find: the error message itself converted 2e99 to an integer (undefined).
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty "
      "float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 "
      "0\n0 1 0\n";
  EXPECT_NE(error_of(header + "3 0 1 2e99\n").find("PLY face 0 refers to vertex 2e+99 of 3"),
            std::string::npos)
      << error_of(header + "3 0 1 2e99\n");
  EXPECT_NE(error_of(header + "3 0 1 -1e300\n").find("refers to vertex -1e+300 of 3"),
            std::string::npos);
}

}  // namespace

namespace {

TEST(PlyCheck, EndHeaderFollowedByOtherBytesOnItsLineIsRefused) {
  // fuzz_mesh's tenth find: assimp 5.2 read for ever after 'end_header' and bytes on its line.
  const std::string start =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty "
      "float z\nelement face 1\nproperty list uchar int vertex_indices\n";
  const std::string data = "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  EXPECT_EQ(error_of(start + "end_header\xff\xff\n" + data),
            "m.ply: PLY 'end_header' is not alone on its line");
  EXPECT_EQ(error_of(start + "xend_header\n" + data),
            "m.ply: PLY 'end_header' is not alone on its line");
  EXPECT_EQ(error_of(start + "end_header \r\n" + data), "");  // trailing blanks are harmless
}

}  // namespace
