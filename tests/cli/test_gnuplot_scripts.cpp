// Text from input files never becomes gnuplot script: robot and link names from a URDF (`audit --report`'s
// heat map) and the text fields of a shard's results.csv (`bench merge`'s plots) that would end a quoted
// string or a line of the script and call gnuplot's `system` or a backquoted command run nothing, and
// the pictures are still drawn. The heat map's own file name (the user's) names that exact file; one
// holding a control character is refused.
#include "cli/tool_run.h"
#include "load/robot_files.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using clearway::test::TempDir;
using clearway_test::runTool;
using clearway_test::slurp;
using clearway_test::ToolRun;

namespace {


// `s` as one word for the shell the tool is run through.
std::string shellWord(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string xmlEscape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\n': out += "&#10;"; break;
      default: out += c;
    }
  }
  return out;
}

// Three boxes on two revolute joints (an Adjacent pair and a sampled one), named as given.
std::string namedUrdf(const std::string& robot, const std::string& link1, const std::string& link2) {
  const std::string a = xmlEscape(link1), b = xmlEscape(link2);
  return "<robot name=\"" + xmlEscape(robot) + "\">\n"
         "  <link name=\"base\"><collision><geometry><box size=\"0.2 0.2 0.2\"/></geometry></collision></link>\n"
         "  <link name=\"" + a + "\"><collision><origin xyz=\"0.5 0 0\"/><geometry><box size=\"0.6 0.1 0.1\"/></geometry></collision></link>\n"
         "  <link name=\"" + b + "\"><collision><origin xyz=\"0.3 0 0\"/><geometry><box size=\"0.4 0.1 0.1\"/></geometry></collision></link>\n"
         "  <joint name=\"j1\" type=\"revolute\"><parent link=\"base\"/><child link=\"" + a + "\"/><origin xyz=\"0 0 0.2\"/><axis xyz=\"0 0 1\"/>\n"
         "    <limit lower=\"-3\" upper=\"3\" velocity=\"1\" effort=\"1\"/></joint>\n"
         "  <joint name=\"j2\" type=\"revolute\"><parent link=\"" + a + "\"/><child link=\"" + b + "\"/><origin xyz=\"1 0 0.15\"/><axis xyz=\"0 0 1\"/>\n"
         "    <limit lower=\"-3\" upper=\"3\" velocity=\"1\" effort=\"1\"/></joint>\n"
         "</robot>\n";
}

bool haveGnuplot() { return std::system("command -v gnuplot >/dev/null 2>&1") == 0; }

// The script holds neither the payload nor any way out of a string or a line into a command.
void expectInert(const std::string& script, const std::string& payload, const std::string& touch) {
  EXPECT_FALSE(script.empty());
  EXPECT_EQ(script.find(payload), std::string::npos) << script;
  EXPECT_EQ(script.find('`'), std::string::npos) << script;
  EXPECT_EQ(script.find(touch + "\""), std::string::npos) << script;
  EXPECT_EQ(script.find(touch + "'"), std::string::npos) << script;
}

}  // namespace

TEST(GnuplotScripts, HostileRobotAndLinkNamesRunNothingInTheHeatMap) {
  TempDir dir;
  const std::string marker = dir.path("ran"), touch = "touch " + marker;
  const std::vector<std::string> payloads = {
      "x\"; system \"" + touch + "\"; print \"",  // ends a "…"
      "x'; system '" + touch + "'; print '",      // ends a '…'
      "x\nsystem \"" + touch + "\"\n#",           // ends the line (the script's first line is a comment naming the robot)
      "x`" + touch + "`",                         // substituted inside "…"
  };
  for (std::size_t k = 0; k < payloads.size(); ++k) {
    SCOPED_TRACE("payload " + std::to_string(k));
    const std::string& p = payloads[k];
    const std::string stem = "r" + std::to_string(k);
    const std::string urdf = dir.write(stem + ".urdf", namedUrdf(p, "a" + p, "b" + p));
    const ToolRun r = runTool("audit " + shellWord(urdf) + " --samples 20 --threads 1 --report " + shellWord(dir.path(stem + ".md")));
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_FALSE(fs::exists(marker)) << "a name ran a command";
    fs::remove(marker);
    expectInert(slurp(dir.path(stem + ".png.gp")), p, touch);
    if (haveGnuplot()) {
      ASSERT_TRUE(fs::exists(dir.path(stem + ".png"))) << r.err;
      EXPECT_GT(fs::file_size(dir.path(stem + ".png")), 1000u);
    }
  }
}

TEST(GnuplotScripts, HeatMapFileNamesWithQuotesAndControlCharacters) {
  TempDir dir;
  const std::string urdf = dir.write("r.urdf", namedUrdf("r", "a", "b"));
  const std::string quoted = "it's \"x\"";
  ToolRun r = runTool("audit " + shellWord(urdf) + " --samples 20 --threads 1 --report " + shellWord(dir.path(quoted + ".md")));
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir.path(quoted + ".png.gp")));
  if (haveGnuplot()) {
    ASSERT_TRUE(fs::exists(dir.path(quoted + ".png"))) << r.err;
    EXPECT_GT(fs::file_size(dir.path(quoted + ".png")), 1000u);
  }
  // No gnuplot string holds a newline: refused before the audit runs.
  r = runTool("audit " + shellWord(urdf) + " --samples 20 --threads 1 --report " +
              shellWord(dir.path("a\nsystem 'touch ran'\n.md")));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_MENTIONS(r.err, "control character");
  EXPECT_FALSE(fs::exists(dir.path("ran")));
}

TEST(GnuplotScripts, HostileResultsFieldsRunNothingInTheBenchPlots) {
  TempDir dir;
  const std::string marker = dir.path("ran"), touch = "touch " + marker;
  // A CSV field holds no comma or newline.
  const std::vector<std::string> payloads = {
      "x'; system '" + touch + "'; print '",      // ends a '…'
      "x\"; system \"" + touch + "\"; print \"",  // ends a "…"
      "x`" + touch + "`",                         // substituted inside "…"
  };
  // One shard of one case: rows of each plotted suite with each text field hostile in turn (subject;
  // engine and mode, which title the curves), and a row of a hostile suite.
  std::ostringstream csv;
  csv << "# clearway bench results v1\n# config: hostile " << payloads[0] << "\n# shard: 0/1\n# cases: 1\n"
      << "suite,case,subject,engine,mode,tolerance,items,ns_per_item,work_per_item,positives,misses,false_alarms,"
         "error,max_error\n";
  int rows = 0;
  for (const std::string& p : payloads) {
    for (const char* suite : {"narrowphase", "states", "motions"}) {
      csv << suite << ",0," << p << "," << p << ",m" << p << ",0.001,10,100,5,3,1,1,1e-6,2e-6\n"
          << suite << ",0,s," << p << ",m" << p << ",0.01,10,50,3,3,2,1,1e-4,3e-4\n"
          << suite << ",0," << p << ",e" << p << ",certified,0.001,10,80,4,3,0,0,1e-7,2e-7\n";
      rows += 3;
    }
    csv << p << ",0,s,e,m,0.001,10,100,5,3,1,1,1e-6,2e-6\n";
    ++rows;
  }
  csv << "# end: " << rows << " rows\n";
  dir.write("s0/results.csv", csv.str());
  const ToolRun r = runTool("bench merge --out " + shellWord(dir.path("m")) + " " + shellWord(dir.path("s0")));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_FALSE(fs::exists(marker)) << "a results.csv field ran a command";
  const std::string script = slurp(dir.path("m/plots.gp"));
  for (const std::string& p : payloads) expectInert(script, p, touch);
  if (haveGnuplot())
    for (const char* png : {"narrowphase.png", "states.png", "motions.png"}) {
      ASSERT_TRUE(fs::exists(dir.path(std::string("m/") + png))) << png << "\n" << r.err;
      EXPECT_GT(fs::file_size(dir.path(std::string("m/") + png)), 1000u) << png;
    }
}
