# cmake -DINPUT=file -DOUTPUT=file.cpp -DNAMESPACE=ns -DFUNCTION=name -P embed_text.cmake
# Writes a C++ source whose function `std::string_view NAMESPACE::FUNCTION()` returns the bytes of
# INPUT, as a raw string literal. Used for the report's bundled script (report/CMakeLists.txt).
file(READ "${INPUT}" text)
string(FIND "${text}" ")mneedle_embed\"" clash)
if(NOT clash EQUAL -1)
  message(FATAL_ERROR "${INPUT} contains the raw-string delimiter )mneedle_embed\"")
endif()
# The text goes inside an inline <script>: it must not end that element early ("</script" in any
# case) or change how the browser finds its end ("<!--").
string(TOLOWER "${text}" lower)
foreach(bad "</script" "<!--")
  string(FIND "${lower}" "${bad}" at)
  if(NOT at EQUAL -1)
    message(FATAL_ERROR "${INPUT} contains ${bad} and cannot be inlined in the report")
  endif()
endforeach()
file(WRITE "${OUTPUT}.tmp"
  "// Generated from ${INPUT} by cmake/embed_text.cmake: do not edit.\n"
  "#include <string_view>\n\nnamespace ${NAMESPACE} {\n\n"
  "std::string_view ${FUNCTION}() {\n"
  "  static constexpr char text[] = R\"mneedle_embed(${text})mneedle_embed\";\n"
  "  return {text, sizeof text - 1};\n}\n\n}  // namespace ${NAMESPACE}\n")
file(RENAME "${OUTPUT}.tmp" "${OUTPUT}")
