// `clearway bench merge`: shards' results.csv files read and merged as the tool merges them. The input
// is one to four files, separated by lines "@@SHARD@@"; each is read (readResults), and the ones read
// are merged (mergeShards). A merge's result must be what an unsharded run writes: every row of the
// shards once, ordered by case, each case within the case count, and its results.csv must read back as
// the same run, row for row.
// Documented: readResults and mergeShards throw std::runtime_error (the tool prints it, exit 2).
#include "fuzz_support.h"

#include "cli/bench_results.h"

#include <stdexcept>
#include <string>
#include <vector>

namespace {

const char* const kSeparator = "\n@@SHARD@@\n";
constexpr std::size_t kMaxShards = 4;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace clearway;
  using namespace clearway::cli;
  const std::string input(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> texts;
  for (std::size_t from = 0; texts.size() < kMaxShards;) {
    const std::size_t cut = input.find(kSeparator, from);
    texts.push_back(input.substr(from, cut == std::string::npos ? std::string::npos : cut - from));
    if (cut == std::string::npos) break;
    from = cut + std::char_traits<char>::length(kSeparator);
  }

  std::vector<BenchResults> shards;
  std::vector<std::string> files;
  std::size_t rows = 0;
  for (std::size_t k = 0; k < texts.size(); ++k) {
    const std::string file = fuzz::writeFile("s" + std::to_string(k) + ".csv", texts[k]);
    BenchResults r;
    if (!fuzz::expectOnly<std::runtime_error>("readResults", [&] { r = readResults(file); })) continue;
    if (r.config.empty() || r.cases < 0 || (r.shard >= 0 && !(r.shard < r.shards)))
      fuzz::finding("readResults accepted a run without a config, or a shard out of range");
    for (const BenchRow& row : r.rows)
      if (row.case_index < 0 || row.case_index >= r.cases) fuzz::finding("readResults accepted a case beyond the case count");
    rows += r.rows.size();
    shards.push_back(std::move(r));
    files.push_back(file);
  }
  if (shards.empty()) return 0;

  BenchResults merged;
  if (!fuzz::expectOnly<std::runtime_error>("mergeShards", [&] { merged = mergeShards(shards, files); })) return 0;
  if (merged.shard != -1 || merged.rows.size() != rows || merged.config != shards[0].config)
    fuzz::finding("mergeShards lost rows or the run's identity");
  for (std::size_t i = 0; i < merged.rows.size(); ++i) {
    if (merged.rows[i].case_index >= merged.cases) fuzz::finding("a merged case beyond the case count");
    if (i > 0 && merged.rows[i - 1].case_index > merged.rows[i].case_index) fuzz::finding("merged rows out of case order");
  }

  // What the merge writes reads back as the same run.
  const std::string out = (fuzz::scratchDir() / "merged.csv").string();
  BenchResults back;
  fuzz::expectOnly<std::runtime_error>("writeResults", [&] { writeResults(out, merged); });
  try {
    back = readResults(out);
  } catch (const std::exception& e) {
    fuzz::finding(std::string("the merged results.csv does not read back: ") + e.what());
  }
  if (back.config != merged.config || back.cases != merged.cases || back.shard != -1 || back.rows.size() != merged.rows.size())
    fuzz::finding("the merged results.csv reads back as another run");
  for (std::size_t i = 0; i < back.rows.size(); ++i)
    if (back.rows[i].line != merged.rows[i].line) fuzz::finding("the merged results.csv reads back with other rows");
  return 0;
}
