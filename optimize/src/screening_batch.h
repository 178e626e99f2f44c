#pragma once
// One screening's state in a process: the designs, which of them an earlier run finished
// (--resume), the result files and the rows so far. screen_designs runs it on threads;
// screen_designs_mpi also deals its designs to other ranks, whose batches only evaluate
// (docs/performance.md, "Screening on a cluster").

#include <atomic>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "mneedle/screening.h"

namespace mneedle {

class ScreeningBatch {
 public:
  /// `writes`: this process records rows (reads --resume rows, writes out/, calls on_row); a
  /// batch that only evaluates (another rank's) touches no file.
  ScreeningBatch(const std::vector<DesignInput>& designs, const Scene& scene,
                 const std::filesystem::path& scene_file, const PluginRegistry& registry,
                 const ScreeningOptions& options, std::function<void(const ScreeningRow&)> on_row,
                 bool writes);
  ~ScreeningBatch();

  std::size_t size() const { return designs_.size(); }
  const DesignInput& design(std::size_t i) const { return designs_[i]; }

  /// What --uncertainty adds to the resume hash ("" without it).
  static std::string uncertainty_key(const ScreeningOptions& o);

  /// The next design to evaluate (input order), or nothing once every design is dealt. A design
  /// an earlier run finished is recorded on the way and never dealt. Thread-safe.
  std::optional<std::size_t> claim();

  /// Evaluates design i; never throws (a failure is the row's error). Thread-safe.
  ScreeningRow evaluate(std::size_t i) const;

  /// Writes design i's finished row to the results and reports it. Thread-safe.
  void record(std::size_t i, ScreeningRow row);

  /// Whether design i has its row.
  bool recorded(std::size_t i);

  /// A digest of the designs' and the scene's hashes: two processes with equal fingerprints
  /// screen the same designs in the same order.
  std::string fingerprint() const;

  /// Every row, in input order (a design never recorded has an empty row).
  std::vector<ScreeningRow> take_rows();

 private:
  const std::vector<DesignInput>& designs_;
  const Scene& scene_;
  const PluginRegistry& registry_;
  const ScreeningOptions& options_;
  std::function<void(const ScreeningRow&)> on_row_;
  std::string scene_text_;
  std::string scene_source_;
  std::string scene_hash_;
  std::string material_;
  std::vector<std::string> hashes_;           // of each design's inputs (the resume key)
  std::map<std::string, ScreeningRow> done_;  // rows of earlier runs, by hash
  std::ofstream jsonl_, csv_;
  std::mutex claim_mutex_, record_mutex_;
  std::size_t next_ = 0;
  std::vector<ScreeningRow> rows_;
  // Set when a row could not be written to out/ (a full disk): no further design is dealt.
  std::string write_error_;
};

/// An error row for design `d` (what a design that fails to evaluate gets).
ScreeningRow screening_error_row(const DesignInput& d, const std::string& message);

/// A row as another rank sent it: what results.jsonl holds for it (`ScreeningRow::json`).
ScreeningRow screening_row_from_json(const std::string& line);

}  // namespace mneedle
