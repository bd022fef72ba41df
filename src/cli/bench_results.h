#pragma once
// `clearway bench`'s results.csv: reading, writing and merging the shards of one run. Rows are kept as
// written (a merge copies them), with their fields parsed for the summary. The format:
//   # clearway bench results v1
//   # config: TEXT           (the configuration; shards of one run share it)
//   # shard: I/N | all
//   # cases: C
//   # ...                    (comments)
//   suite,case,subject,...   (kBenchColumns, then one row per line)
//   # end: R rows            (last: a file cut short anywhere lacks it)
#include <string>
#include <vector>

namespace clearway::cli {

/// The column line of results.csv.
constexpr const char* kBenchColumns =
    "suite,case,subject,engine,mode,tolerance,items,ns_per_item,work_per_item,positives,misses,false_alarms,"
    "error,max_error";

/// One row: a case's figures for one engine, mode and tolerance.
struct BenchRow {
  long case_index = 0;
  std::string suite, subject, engine, mode;
  double tolerance = 0, items = 0, ns = 0, work = 0, positives = 0, misses = 0, false_alarms = 0, error = 0,
         max_error = 0;
  std::string line;  ///< as written: merges copy it
};

/// The identity of a run (its configuration line, the shard and the number of cases) and its rows.
struct BenchResults {
  std::string config;
  long shard = -1, shards = 0;  ///< shard I of N; -1: all cases
  long cases = 0;
  std::vector<BenchRow> rows;
};

/// The fields of `s` between the separators (an empty field where two meet or one ends `s`).
std::vector<std::string> splitFields(const std::string& s, char sep);

/// "I/N" with 0 ≤ I < N; false with `why` set otherwise.
bool parseShard(const std::string& s, long& index, long& count, std::string& why);

/// A row line. Throws std::runtime_error naming `where`, the field and the reason.
BenchRow parseRow(const std::string& line, const std::string& where);

/// Reads a results.csv. Throws std::runtime_error naming the file, the line and the reason for a file
/// that cannot be opened or is not one, a bad line or row, a config, shard or cases line given twice or
/// after the column line, or a file cut short.
BenchResults readResults(const std::string& file);

/// Writes `res` as a results.csv. Throws std::runtime_error when the file cannot be written.
void writeResults(const std::string& file, const BenchResults& res);

/// Shards 0 … N−1 of one run, each once, as that run (shard −1): their rows ordered by case, as an
/// unsharded run writes them. `files[k]` names shards[k] in errors. Throws std::runtime_error naming the
/// file for an unsharded result, another configuration or shard count, a shard given twice or missing,
/// or a row whose case belongs to another shard.
BenchResults mergeShards(const std::vector<BenchResults>& shards, const std::vector<std::string>& files);

}  // namespace clearway::cli
