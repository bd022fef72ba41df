// `clearway audit`'s SRDF: written over the shared Panda's SRDF it keeps every element srdfdom reads
// (groups, group states, end effector, virtual and passive joints) and the comments, and replaces only
// the disable_collisions (link1 < link2, sorted); --check passes on what it wrote and fails on a drifted
// copy; link names that XML must escape stay well-formed; --srdf-out - writes the SRDF alone to stdout;
// --threads and the usage errors.
#include "cli/tool_run.h"
#include "load/robot_files.h"
#include "srdf_reader.h"

#include <clearway/load/robot_loader.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <thread>

using clearway::test::readSrdfText;
using clearway::test::SrdfContent;
using clearway::test::TempDir;
using clearway_test::runTool;
using clearway_test::slurp;
using clearway_test::ToolRun;

namespace {


std::string q(const std::string& path) { return "'" + path + "'"; }

// The audit's disable_collisions are each pair once, link1 < link2, sorted, with a MoveIt reason.
void expectSortedPairs(const SrdfContent& srdf) {
  for (std::size_t k = 0; k < srdf.disabled.size(); ++k) {
    const SrdfContent::Pair& p = srdf.disabled[k];
    EXPECT_LT(p.link1, p.link2);
    EXPECT_TRUE(p.reason == "Adjacent" || p.reason == "Default" || p.reason == "Always" || p.reason == "Never") << p.reason;
    if (k > 0) {
      const SrdfContent::Pair& o = srdf.disabled[k - 1];
      EXPECT_TRUE(o.link1 < p.link1 || (o.link1 == p.link1 && o.link2 < p.link2)) << o.link1 << " " << o.link2 << " before "
                                                                                 << p.link1 << " " << p.link2;
    }
  }
}

// A robot whose link names XML must escape: arm&1 and it's"2" (written escaped in the URDF).
const char* kEscapedUrdf = R"(<robot name="esc&amp;bot">
  <link name="base"><collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
  <link name="arm&amp;1"><collision><origin xyz="0.5 0 0"/><geometry><box size="0.6 0.1 0.1"/></geometry></collision></link>
  <link name="it's&quot;2&quot;"><collision><origin xyz="0.3 0 0"/><geometry><box size="0.4 0.1 0.1"/></geometry></collision></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="arm&amp;1"/><origin xyz="0 0 0.2"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" velocity="1" effort="1"/></joint>
  <joint name="j2" type="revolute"><parent link="arm&amp;1"/><child link="it's&quot;2&quot;"/><origin xyz="1 0 0.15"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" velocity="1" effort="1"/></joint>
</robot>)";

}  // namespace

TEST(AuditTool, PandaSrdfRoundTripAndCheck) {
  CLEARWAY_SHARED_ROBOT_OR_SKIP(urdf, "panda/panda.urdf");
  CLEARWAY_SHARED_ROBOT_OR_SKIP(shipped, "panda/panda.srdf");
  TempDir dir;
  // Written over the input, as a user refreshing a robot's SRDF does.
  const std::string srdf = dir.write("panda.srdf", slurp(shipped));
  const std::string audit = "audit " + q(urdf) + " --samples 300 --seed 2 --threads 2";
  ToolRun r = runTool(audit + " --srdf " + q(srdf) + " --srdf-out " + q(srdf));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_MENTIONS(r.err, "2 threads");
  const SrdfContent before = readSrdfText(slurp(shipped)), after = readSrdfText(slurp(srdf));
  ASSERT_TRUE(before.errors.empty()) << before.errors.front();
  for (const std::string& e : after.errors) ADD_FAILURE() << e;
  EXPECT_EQ(after.unknown, before.unknown);
  // Everything srdfdom reads but the disabled pairs is as it was, in the same order; so are the comments.
  EXPECT_EQ(after.robot_name, "panda");
  EXPECT_EQ(after.semantic, before.semantic);
  EXPECT_EQ(before.groups, 3);
  EXPECT_EQ(before.group_states, 5);
  EXPECT_EQ(before.end_effectors, 1);
  EXPECT_EQ(before.virtual_joints, 1);
  // Its passive joint is inside the hand group, which srdfdom skips but a writer must keep.
  EXPECT_NE(std::find(after.semantic.begin(), after.semantic.end(),
                      "group hand: link(panda_hand) link(panda_leftfinger) link(panda_rightfinger) "
                      "joint(panda_finger_joint1) passive_joint(panda_finger_joint2)"),
            after.semantic.end());
  EXPECT_EQ(after.comments, before.comments);
  EXPECT_GT(after.disabled.size(), 20u);  // 10 Adjacent, and the pairs the samples never saw collide
  expectSortedPairs(after);
  // It loads back as MoveIt would load it, one disabled pair per element.
  EXPECT_EQ(clearway::loadRobot(urdf, srdf).disabledCollisions().size(), after.disabled.size());

  // --check agrees with what the same audit wrote, and fails when the SRDF drifts: a pair dropped.
  r = runTool(audit + " --check --srdf " + q(srdf));
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_MENTIONS(r.out, "0 pairs differ");
  std::string drifted = slurp(srdf);
  const std::size_t line = drifted.find("  <disable_collisions link1=\"panda_link0\" link2=\"panda_link1\"");
  ASSERT_NE(line, std::string::npos) << drifted;
  drifted.erase(line, drifted.find('\n', line) + 1 - line);
  r = runTool(audit + " --check --srdf " + q(dir.write("drifted.srdf", drifted)));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_MENTIONS(r.out, "differs: panda_link0 panda_link1: SRDF checked, audit Adjacent");
  EXPECT_MENTIONS(r.err, "--check: " + dir.path("drifted.srdf") + " disagrees with the audit");
}

TEST(AuditTool, LinkNamesThatXmlEscapesAndStdout) {
  TempDir dir;
  const std::string urdf = dir.write("esc.urdf", kEscapedUrdf);
  const ToolRun r = runTool("audit " + q(urdf) + " --samples 50 --srdf-out -");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // stdout is the SRDF alone (the report went to stderr), and it is well-formed.
  EXPECT_EQ(r.out.rfind("<?xml", 0), 0u) << r.out;
  EXPECT_MENTIONS(r.err, "3 pairs");
  const SrdfContent srdf = readSrdfText(r.out);
  for (const std::string& e : srdf.errors) ADD_FAILURE() << e << "\n" << r.out;
  EXPECT_EQ(srdf.robot_name, "esc&bot");
  ASSERT_FALSE(srdf.disabled.empty()) << r.out;
  EXPECT_EQ(srdf.disabled[0].link1, "arm&1");  // Adjacent; by name arm&1 < base < it's"2"
  EXPECT_EQ(srdf.disabled[0].link2, "base");
  expectSortedPairs(srdf);
  EXPECT_EQ(clearway::loadRobot(urdf, dir.write("esc.srdf", r.out)).disabledCollisions().size(), srdf.disabled.size());
}

TEST(AuditTool, ThreadsAndUsageErrors) {
  TempDir dir;
  const std::string urdf = dir.write("esc.urdf", kEscapedUrdf);
  // The default is one thread per hardware thread.
  ToolRun r = runTool("audit " + q(urdf) + " --samples 10");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_MENTIONS(r.err, std::to_string(std::max(1u, std::thread::hardware_concurrency())) + " threads");
  r = runTool("audit " + q(urdf) + " --threads 0");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_MENTIONS(r.err, "--threads: needs a whole number from 1 to 1024, got '0'");
  r = runTool("audit " + q(urdf) + " --check");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_MENTIONS(r.err, "--check needs the --srdf to compare with");
  r = runTool("audit " + q(urdf) + " --report -");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_MENTIONS(r.err, "--report needs a file name");
  r = runTool("audit " + q(urdf) + " --samples 10 --srdf-out " + q(dir.path("no/such/folder/out.srdf")));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_MENTIONS(r.err, "cannot write " + dir.path("no/such/folder/out.srdf"));
  // A report that cannot be written is an error too, never exit 0 (issue 43 §5).
  r = runTool("audit " + q(urdf) + " --samples 10 --report " + q(dir.path("no/such/folder/report.md")));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_MENTIONS(r.err, "cannot write " + dir.path("no/such/folder/report.md"));
}

// --threads 600 started 600 threads (and aborted where they could not be created): the audit uses at
// most 4 per hardware thread, 256 in all, and says so.
TEST(AuditTool, ThreadsBeyondTheCapAreCappedWithAWarning) {
  TempDir dir;
  const std::string urdf = dir.write("esc.urdf", kEscapedUrdf);
  const int cap = static_cast<int>(std::min(256u, 4 * std::max(1u, std::thread::hardware_concurrency())));
  const ToolRun r = runTool("audit " + q(urdf) + " --samples 20 --threads 600");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_MENTIONS(r.err, "--threads 600 is more than this machine runs at once: " + std::to_string(cap) + " threads used");
  EXPECT_MENTIONS(r.err, std::to_string(cap) + " threads\n");
}
