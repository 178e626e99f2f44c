// OFF structure checked before assimp: the header's counts (assimp allocates for every declared
// vertex first), each vertex's coordinates and each face's indices.
#include "needle/off_check.h"

#include <gtest/gtest.h>

#include <string>

#include "mneedle/base/error.h"

namespace {

std::string error_of(const std::string& bytes) {
  try {
    mneedle::off::check_structure("m.off", bytes);
  } catch (const mneedle::InputError& e) {
    return e.what();
  }
  return "";
}

const std::string kTriangleData = "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";

TEST(OffCheck, CompleteFilesPassWithOrWithoutKeywordCommentsOrSharedHeaderLine) {
  EXPECT_EQ(error_of("OFF\n3 1 0\n" + kTriangleData), "");
  EXPECT_EQ(error_of("OFF 3 1 0\n" + kTriangleData), "");
  EXPECT_EQ(error_of("# made by hand\nOFF\n# counts\n3 1 0\n\n" + kTriangleData), "");
  EXPECT_EQ(error_of("3 1 0\n" + kTriangleData), "");  // the keyword is optional
  EXPECT_EQ(error_of("COFF\n3 1 0\n" + kTriangleData), "");
  EXPECT_EQ(error_of("nOFF 3\n3 1 0\n" + kTriangleData), "");  // nOFF carries a dimension
}

TEST(OffCheck, CountsBeyondTheDataAreRefusedBeforeAnyoneAllocatesForThem) {
  // fuzz_mesh's ninth find: assimp 5.2 spent 50 s zero-filling 2e9 declared vertices.
  const std::string message = error_of("OFF\n2000000000 1 0\n" + kTriangleData);
  EXPECT_EQ(message,
            "m.off: OFF header declares 2000000000 vertices and 1 faces but the data has "
            "4 lines");
  EXPECT_NE(error_of("OFF\n3 2 0\n" + kTriangleData).find("3 vertices and 2 faces"),
            std::string::npos);
}

TEST(OffCheck, MissingOrNonIntegerCountsAreRefusedWithTheirLine) {
  EXPECT_EQ(error_of("OFF\n3 1\n"),
            "m.off: OFF header ends before its vertex, face and edge counts");
  EXPECT_EQ(error_of("OFF\n3 -1 0\n" + kTriangleData),
            "m.off: OFF header line 2: '-1' is not a vertex, face or edge count (a whole number "
            ">= 0)");
  EXPECT_NE(error_of("OFF\n3 1e30 0\n" + kTriangleData).find("'1e30'"), std::string::npos);
  EXPECT_NE(error_of("OFF\n99999999999999999999 1 0\n" + kTriangleData).find("is not a vertex"),
            std::string::npos);
}

// A fuzzer's input that crashed assimp in a later step: a face line with a word where its
// fourth index belongs (tests/fuzz/corpus/mesh_regressions/off_face_index_is_a_word).
TEST(OffCheck, AFaceMustListItsCornerCountAndThatManyIndicesOfDeclaredVertices) {
  EXPECT_EQ(error_of("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 vertex\n"),
            "m.off: OFF line 6: face 0: 'vertex' is not the index of one of its 3 vertices");
  EXPECT_EQ(error_of("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"),
            "m.off: OFF line 6: face 0: '3' is not the index of one of its 3 vertices");
  EXPECT_EQ(error_of("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1\n"),
            "m.off: OFF line 6: face 0: fewer indices than its 3 corners");
  EXPECT_EQ(error_of("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n"),
            "m.off: OFF line 6: face 0: '2' is not a corner count (a whole number from 3 to 9, "
            "what assimp reads)");
  // assimp drops a face of more than 9 corners, leaving a hole.
  EXPECT_NE(error_of("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n10 0 1 2 0 1 2 0 1 2 0\n")
                .find("'10' is not a corner count"),
            std::string::npos);
  // Colours after the indices are the format's own and pass.
  EXPECT_EQ(error_of("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2 255 0 0\n"), "");
}

TEST(OffCheck, AVertexMustHoldThreeFiniteCoordinates) {
  EXPECT_EQ(error_of("OFF\n3 1 0\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n"),
            "m.off: OFF line 4: vertex 1 needs three finite coordinates");
  EXPECT_NE(error_of("OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n").find("('nan' is not one)"),
            std::string::npos);
}

// Lines end where assimp ends them: at '\n', '\r' (alone or before '\n') or '\f'. A face hidden
// behind a lone '\r' (the fuzzer's face again, read by assimp as a face of its own) is checked as
// one; a line assimp would cut at its 4096-byte buffer is refused.
TEST(OffCheck, LinesEndWhereAssimpEndsThemAndNoneOutgrowsItsBuffer) {
  const std::string vertices = "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n";
  EXPECT_EQ(error_of(vertices + "3 0 1 2\r3 0 1 vertex\n"),
            "m.off: OFF line 7: face 1: 'vertex' is not the index of one of its 3 vertices");
  EXPECT_EQ(error_of("OFF\r\n3 1 0\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n3 0 1 2\r\n"), "");
  EXPECT_EQ(error_of("OFF\r3 1 0\r0 0 0\r1 0 0\r0 1 0\f3 0 1 2\r"), "");
  EXPECT_EQ(error_of(vertices + "3 0 1 2 " + std::string(4100, '0') + "\n3 0 1 2\n"),
            "m.off: OFF line 6 is longer than 4095 characters");
}

}  // namespace
