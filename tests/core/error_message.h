#pragma once
// The message of the error a call throws, for tests that check one-line error texts: the
// exception's what(), or "no <kind>" when the call throws nothing.

#include <string>

namespace mneedle::testing {

template <class Error, class Call>
std::string error_message(const Call& call) {
  try {
    call();
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace mneedle::testing
