#pragma once
#include <stdexcept>
#include <string>

namespace mneedle {

/// Bad input from a user: a file, a field or a value. The message is one line naming
/// where (file, file:line or key) and what is wrong; the CLI prints it and exits non-zero.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A computation that cannot deliver a trustworthy number (no convergence, singular system).
class SolverError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A computation refused before it allocated what would not fit in the memory left
/// (require_memory): a shorter step or another try needs as much, so retry loops pass it on.
class OutOfMemoryError : public SolverError {
 public:
  using SolverError::SolverError;
};

}  // namespace mneedle
