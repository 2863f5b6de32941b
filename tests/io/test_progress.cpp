// io::Progress: its lines on standard error by default, or to the ProgressSink alive on the thread that made it
// (the Python module's route to sys.stderr, which Jupyter shows), from worker threads too; sinks nest.
#include <gtest/gtest.h>

#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "afmkit/io/progress.hpp"

using afmkit::io::Progress;
using afmkit::io::ProgressSink;

namespace {

struct ProgressLinesSeen {
  std::mutex mutex;
  std::vector<std::string> lines;
  afmkit::io::ProgressLines sink() {
    return [this](const std::string& line) {
      std::lock_guard<std::mutex> lock(mutex);
      lines.push_back(line);
    };
  }
};

}  // namespace

TEST(ProgressSink, LinesGoToTheSinkNotToStandardError) {
  ProgressLinesSeen seen;
  testing::internal::CaptureStderr();
  {
    ProgressSink sink(seen.sink());
    Progress p("points", 4, true, 0.0);  // interval 0: a line per advance
    p.advance();
    p.advance(3);
    p.finish();
  }
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
  ASSERT_EQ(seen.lines.size(), 3u);
  EXPECT_EQ(seen.lines[0], "points: 1/4 (25%)");
  EXPECT_EQ(seen.lines[1], "points: 4/4 (100%)");
  EXPECT_EQ(seen.lines[2].rfind("points: done, 4 items in ", 0), 0u) << seen.lines[2];
}

TEST(ProgressSink, WithoutASinkLinesGoToStandardErrorAndASinkEndsWithItsScope) {
  ProgressLinesSeen seen;
  { ProgressSink sink(seen.sink()); }
  testing::internal::CaptureStderr();
  Progress p("turns", 2, true, 0.0);
  p.advance(2);
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "turns: 2/2 (100%)\n");
  EXPECT_TRUE(seen.lines.empty());
}

TEST(ProgressSink, AProgressKeepsItsSinkOnWorkerThreadsAndSinksNest) {
  ProgressLinesSeen outer, inner;
  ProgressSink a(outer.sink());
  constexpr int rounds = 200;  // a line lost to a race between the workers shows within a few rounds
  for (int round = 0; round < rounds; ++round) {
    ProgressSink b(inner.sink());
    Progress p("grid", 8, true, 0.0);
    std::vector<std::thread> workers;
    for (int i = 0; i < 4; ++i) workers.emplace_back([&p] { p.advance(2); });  // no sink on these threads
    for (auto& w : workers) w.join();
  }
  Progress q("after", 1, true, 0.0);  // the inner sink is gone: the outer one again
  q.advance();
  EXPECT_EQ(inner.lines.size(), 4u * rounds);  // interval 0: a line per advance, whichever thread waited
  ASSERT_EQ(outer.lines.size(), 1u);
  EXPECT_EQ(outer.lines[0], "after: 1/1 (100%)");
}

TEST(ProgressSink, ADisabledProgressSendsNothing) {
  ProgressLinesSeen seen;
  ProgressSink sink(seen.sink());
  Progress p("quiet", 3, false, 0.0);
  p.advance(3);
  p.finish();
  EXPECT_TRUE(seen.lines.empty());
}

TEST(ProgressSink, ACommandsWarningGoesWhereItsProgressGoes) {
  ProgressLinesSeen seen;
  testing::internal::CaptureStderr();
  afmkit::io::message_line("afmkit: warning: before");
  {
    ProgressSink sink(seen.sink());
    afmkit::io::message_line("afmkit: warning: inside");
  }
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "afmkit: warning: before\n");
  ASSERT_EQ(seen.lines.size(), 1u);
  EXPECT_EQ(seen.lines[0], "afmkit: warning: inside");
}
