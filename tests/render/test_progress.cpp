// The terminal progress line (app/progress.hpp): silent unless stderr is a terminal and the run is
// long; one redrawn line with percentage and estimate; erased at the end. app/ is not a library,
// so its one source file is compiled into this test directly.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "../app/progress.cpp"

namespace drape::app {
namespace {

std::string contents(std::FILE* f) {
  std::fflush(f);
  std::rewind(f);
  std::string s;
  for (int c = std::fgetc(f); c != EOF; c = std::fgetc(f)) s.push_back(static_cast<char>(c));
  std::fseek(f, 0, SEEK_END);  // back to writing
  return s;
}

TEST(Progress, SilentWhenNotATerminalOrShort) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  {
    Progress pipe("draping", 10, f, /*is_terminal=*/false, /*quiet_seconds=*/0.0);
    for (int i = 0; i <= 10; ++i) pipe.update(i, "step");
    EXPECT_FALSE(pipe.shown());
    Progress quick("draping", 10, f, /*is_terminal=*/true, /*quiet_seconds=*/3600.0);
    for (int i = 0; i <= 10; ++i) quick.update(i);
    EXPECT_FALSE(quick.shown());
  }
  EXPECT_EQ(contents(f), "");
  std::fclose(f);
}

TEST(Progress, DrawsOneLineAndErasesIt) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  Progress p("draping", 10, f, /*is_terminal=*/true, /*quiet_seconds=*/0.0);
  p.update(5, "settling");
  EXPECT_TRUE(p.shown());
  const std::string line = contents(f);
  EXPECT_EQ(line.front(), '\r');
  EXPECT_EQ(line.find('\n'), std::string::npos);
  EXPECT_NE(line.find("draping ["), std::string::npos) << line;
  EXPECT_NE(line.find(" 50% 5/10"), std::string::npos) << line;
  EXPECT_NE(line.find("left"), std::string::npos) << line;
  EXPECT_NE(line.find("(settling)"), std::string::npos) << line;
  p.finish();
  EXPECT_FALSE(p.shown());
  const std::string erased = contents(f);
  EXPECT_EQ(erased.substr(erased.size() - 4), "\r\x1b[K");
  p.finish();  // idempotent
  EXPECT_EQ(contents(f), erased);
  std::fclose(f);
}

TEST(Progress, UnknownTotalAndLongDetailFitTheLine) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  Progress p("frames", 0, f, /*is_terminal=*/true, /*quiet_seconds=*/0.0);
  p.update(42, std::string(500, 'x'));
  const std::string line = contents(f);
  EXPECT_NE(line.find("frames 42 done"), std::string::npos) << line;
  EXPECT_EQ(line.find('%'), std::string::npos);
  // "\r" + at most 79 visible characters (80 columns when the output is not a terminal) + "\x1b[K".
  EXPECT_LE(line.size(), 1u + 79u + 3u);
  p.finish();  // before the file closes
  std::fclose(f);
}

}  // namespace
}  // namespace drape::app
