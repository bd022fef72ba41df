#include "bench_results.h"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

namespace clearway::cli {

namespace {

constexpr int kFields = 14;

bool parseLong(const std::string& s, long& out) {
  if (s.empty()) return false;
  char* end = nullptr;
  errno = 0;
  out = std::strtol(s.c_str(), &end, 10);
  return errno == 0 && *end == '\0';
}

bool parseDouble(const std::string& s, double& out) {
  if (s.empty()) return false;
  char* end = nullptr;
  out = std::strtod(s.c_str(), &end);
  return *end == '\0';
}

}  // namespace

std::vector<std::string> splitFields(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream in(s);
  std::string field;
  while (std::getline(in, field, sep)) out.push_back(field);
  if (!s.empty() && s.back() == sep) out.emplace_back();
  return out;
}

bool parseShard(const std::string& s, long& index, long& count, std::string& why) {
  const auto slash = s.find('/');
  if (slash == std::string::npos || !parseLong(s.substr(0, slash), index) || !parseLong(s.substr(slash + 1), count)) {
    why = "expected I/N, two integers";
    return false;
  }
  if (count < 1 || index < 0 || index >= count) {
    why = "the index must be in [0, N) and N at least 1";
    return false;
  }
  return true;
}

BenchRow parseRow(const std::string& line, const std::string& where) {
  const std::vector<std::string> f = splitFields(line, ',');
  if (static_cast<int>(f.size()) != kFields) throw std::runtime_error(where + ": expected " + std::to_string(kFields) +
                                                                       " fields, found " + std::to_string(f.size()));
  BenchRow r;
  r.line = line;
  r.suite = f[0], r.subject = f[2], r.engine = f[3], r.mode = f[4];
  double* numbers[] = {&r.tolerance, &r.items, &r.ns, &r.work, &r.positives, &r.misses, &r.false_alarms, &r.error,
                       &r.max_error};
  if (!parseLong(f[1], r.case_index) || r.case_index < 0) throw std::runtime_error(where + ": bad case index '" + f[1] + "'");
  for (int k = 0; k < 9; ++k)
    if (!parseDouble(f[5 + k], *numbers[k]))
      throw std::runtime_error(where + ": field " + std::to_string(6 + k) + " is not a number: '" + f[5 + k] + "'");
  return r;
}

BenchResults readResults(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error("cannot open " + file + ": " + std::strerror(errno));
  BenchResults res;
  std::string line;
  int n = 0;
  bool header = false, seen_config = false, seen_shard = false, seen_cases = false, seen_end = false;
  while (std::getline(in, line)) {
    const std::string where = file + ":" + std::to_string(++n);
    if (n == 1 && line != "# clearway bench results v1") throw std::runtime_error(where + ": not a clearway bench results file");
    // The run's identity, once each and before the rows: a case count given again after some rows would
    // leave them beyond it.
    const auto identity = [&](bool& seen, const char* what) {
      if (seen) throw std::runtime_error(where + ": a second " + what + " line");
      if (header) throw std::runtime_error(where + ": the " + what + " line comes after the column line");
      seen = true;
    };
    if (line.rfind("# config: ", 0) == 0) {
      identity(seen_config, "config");
      res.config = line.substr(10);
    } else if (line.rfind("# shard: ", 0) == 0) {
      identity(seen_shard, "shard");
      const std::string s = line.substr(9);
      std::string why;
      if (s != "all" && !parseShard(s, res.shard, res.shards, why)) throw std::runtime_error(where + ": shard '" + s + "': " + why);
    } else if (line.rfind("# cases: ", 0) == 0) {
      identity(seen_cases, "cases");
      seen_cases = parseLong(line.substr(9), res.cases) && res.cases >= 0;
      if (!seen_cases) throw std::runtime_error(where + ": bad case count");
    } else if (line.rfind("# end: ", 0) == 0) {
      // Written last: a file cut short anywhere (even inside a number of the last row) lacks it.
      long count = -1;
      seen_end = parseLong(line.substr(7, line.find(' ', 7) - 7), count) && count == static_cast<long>(res.rows.size());
      if (!seen_end) throw std::runtime_error(where + ": the end line does not match the " + std::to_string(res.rows.size()) + " rows read");
    } else if (seen_end) {
      throw std::runtime_error(where + ": text after the end line");
    } else if (line.rfind("#", 0) == 0) {
      continue;
    } else if (!header) {
      if (line != kBenchColumns) throw std::runtime_error(where + ": unexpected column header");
      header = true;
    } else {
      res.rows.push_back(parseRow(line, where));
      if (res.rows.back().case_index >= res.cases) throw std::runtime_error(where + ": case index beyond the case count");
    }
  }
  if (!header || res.config.empty() || !seen_shard || !seen_cases || !seen_end)
    throw std::runtime_error(file + ": truncated: the config, shard, cases, column or end lines are missing");
  return res;
}

void writeResults(const std::string& file, const BenchResults& res) {
  std::ofstream out(file);
  out << "# clearway bench results v1\n# config: " << res.config << "\n# shard: "
      << (res.shard < 0 ? std::string("all") : std::to_string(res.shard) + "/" + std::to_string(res.shards))
      << "\n# cases: " << res.cases << "\n"
      << "# ns_per_item is thread CPU time (planning: median solve time); every other field depends only on\n"
      << "# the config and the case\n"
      << kBenchColumns << "\n";
  for (const BenchRow& r : res.rows) out << r.line << "\n";
  out << "# end: " << res.rows.size() << " rows\n";
  out.flush();
  if (!out) throw std::runtime_error("cannot write " + file);
}

BenchResults mergeShards(const std::vector<BenchResults>& shards, const std::vector<std::string>& files) {
  if (shards.empty()) throw std::runtime_error("no shards to merge");
  BenchResults merged;
  std::set<long> seen;  // the shards given (not a flag per shard: N may be anything a file says)
  for (std::size_t k = 0; k < shards.size(); ++k) {
    const BenchResults& shard = shards[k];
    const std::string& file = files[k];
    if (shard.shard < 0) throw std::runtime_error(file + ": not a shard (its shard line says all)");
    if (merged.config.empty()) merged.config = shard.config, merged.cases = shard.cases, merged.shards = shard.shards;
    if (shard.config != merged.config) throw std::runtime_error(file + ": another configuration: " + shard.config);
    if (shard.shards != merged.shards || shard.cases != merged.cases)
      throw std::runtime_error(file + ": shard " + std::to_string(shard.shard) + "/" + std::to_string(shard.shards) +
                               " of " + std::to_string(shard.cases) + " cases does not match the first shard");
    if (!seen.insert(shard.shard).second) throw std::runtime_error(file + ": shard " + std::to_string(shard.shard) + " given twice");
    for (const BenchRow& r : shard.rows)
      if (r.case_index % shard.shards != shard.shard)
        throw std::runtime_error(file + ": case " + std::to_string(r.case_index) + " does not belong to this shard");
    merged.rows.insert(merged.rows.end(), shard.rows.begin(), shard.rows.end());
  }
  // The first shard missing: shards 0 … N−1 given once each are N shards, so one is missing while fewer
  // were given, and it lies among the first few.
  if (static_cast<long>(seen.size()) < merged.shards) {
    long missing = 0;
    while (seen.count(missing) > 0) ++missing;
    throw std::runtime_error("shard " + std::to_string(missing) + "/" + std::to_string(merged.shards) + " is missing");
  }
  merged.shard = -1, merged.shards = 0;
  std::stable_sort(merged.rows.begin(), merged.rows.end(),
                   [](const BenchRow& a, const BenchRow& b) { return a.case_index < b.case_index; });
  return merged;
}

}  // namespace clearway::cli
