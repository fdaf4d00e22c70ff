// CommandLine: values in both spellings, defaults kept, required options, integers checked
// against their range, unknown / abbreviated / repeated / positional arguments refused with a
// message naming them, --help listing every option with its default (exit 0), and a bad
// command line giving exactly one line with the usage (exit 2).
#include <gtest/gtest.h>

#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "ipm_road_mapper/pipeline/command_line.h"

namespace ipm_road_mapper {
namespace {

// A tool with one option of each kind.
struct Tool {
  std::string bag, config = "default.yaml";
  std::int64_t seed = 0, frames = 0;
  bool async = false;
  CommandLine line{"tool", "Maps a bag."};

  Tool() {
    line.Required("bag", "<bag>", &bag, "the bag to map")
        .Optional("config", "<yaml>", &config, "config/mapper.yaml of the package", "mapper config")
        .Integer("seed", "<n>", &seed, 0, 4294967295LL, true, "", "random seed")
        .Integer("max-frames", "<n>", &frames, 1, 1000000, false, "every frame", "frames to render")
        .Flag("async", &async, "keep the config's threading");
  }

  bool Parse(std::vector<const char*> args) {
    args.insert(args.begin(), "tool");
    return line.Parse(static_cast<int>(args.size()), args.data());
  }

  // The CommandLineError message of a parse that must fail.
  std::string Error(std::vector<const char*> args) {
    try {
      Parse(std::move(args));
    } catch (const CommandLineError& e) {
      return e.what();
    }
    return "(no error)";
  }
};

TEST(CommandLineTest, ParsesBothSpellingsAndKeepsDefaults) {
  Tool tool;
  ASSERT_TRUE(tool.Parse({"--bag", "a.bag", "--seed=7"}));
  EXPECT_EQ(tool.bag, "a.bag");
  EXPECT_EQ(tool.seed, 7);
  EXPECT_EQ(tool.config, "default.yaml");
  EXPECT_EQ(tool.frames, 0);
  EXPECT_FALSE(tool.async);
  Tool other;
  ASSERT_TRUE(other.Parse(
      {"--async", "--config=c.yaml", "--bag=b.bag", "--seed", "4294967295", "--max-frames", "40"}));
  EXPECT_EQ(other.bag, "b.bag");
  EXPECT_EQ(other.config, "c.yaml");
  EXPECT_EQ(other.seed, 4294967295LL);
  EXPECT_EQ(other.frames, 40);
  EXPECT_TRUE(other.async);
}

TEST(CommandLineTest, BadCommandLinesNameTheOption) {
  Tool tool;
  EXPECT_EQ(tool.Error({"--bag", "a", "--seed", "1", "--fast"}), "unknown argument '--fast'");
  EXPECT_EQ(tool.Error({"--seed", "1"}), "missing --bag");
  EXPECT_EQ(tool.Error({"--bag", "a"}), "missing --seed");
  EXPECT_EQ(tool.Error({"--seed", "1", "--bag"}), "--bag needs a value");
  EXPECT_EQ(tool.Error({"--bag", "a", "--bag", "b", "--seed", "1"}), "option --bag given twice");
  EXPECT_EQ(tool.Error({"--bag", "a", "--seed", "1", "--async=yes"}), "--async takes no value");
  EXPECT_EQ(tool.Error({"--bag", "a", "--seed", "1", "extra"}), "unexpected argument 'extra'");
  // No abbreviations: --conf is not --config.
  EXPECT_EQ(tool.Error({"--bag", "a", "--seed", "1", "--conf", "c"}), "unknown argument '--conf'");
}

TEST(CommandLineTest, IntegersAreCheckedAgainstTheirRange) {
  Tool tool;
  EXPECT_EQ(tool.Error({"--bag", "a", "--seed", "x1"}),
            "--seed: expected an integer in [0, 4294967295], got 'x1'");
  EXPECT_EQ(tool.Error({"--bag", "a", "--seed", "4294967296"}),
            "--seed: expected an integer in [0, 4294967295], got '4294967296'");
  EXPECT_EQ(tool.Error({"--bag", "a", "--seed", "1", "--max-frames", "0"}),
            "--max-frames: expected an integer in [1, 1000000], got '0'");
  EXPECT_EQ(tool.Error({"--bag", "a", "--seed", "1.5"}),
            "--seed: expected an integer in [0, 4294967295], got '1.5'");
  EXPECT_THROW(ParseIntegerOption("--n", "99999999999999999999", 0, INT64_MAX), CommandLineError);
  try {
    ParseIntegerOption("--map-bytes", "-1", 0, INT64_MAX);
    FAIL() << "-1 accepted";
  } catch (const CommandLineError& e) {
    EXPECT_STREQ(e.what(), "--map-bytes: expected an integer >= 0, got '-1'");
  }
}

TEST(CommandLineTest, HelpListsEveryOptionWithItsDefault) {
  for (const char* flag : {"--help", "-h"}) {
    Tool tool;
    EXPECT_FALSE(tool.Parse({"--bag", "a", flag})) << flag;
    EXPECT_FALSE(tool.Parse({flag})) << flag << " needs no required option";
  }
  Tool tool;
  const std::string help = tool.line.Help();
  EXPECT_EQ(help.rfind(tool.line.Usage() + "\n\nMaps a bag.\n", 0), 0u) << help;
  for (const char* expected :
       {"--bag <bag>", "the bag to map (required)", "--config <yaml>",
        "(default: config/mapper.yaml of the package)", "--seed <n>", "random seed (required)",
        "--max-frames <n>", "(default: every frame)", "--async", "(default: off)", "--help"}) {
    EXPECT_NE(help.find(expected), std::string::npos) << expected << " in\n" << help;
  }
  EXPECT_EQ(tool.line.Usage(),
            "usage: tool --bag <bag> [--config <yaml>] --seed <n> [--max-frames <n>] [--async]");
}

TEST(CommandLineTest, ExitCodesAndOneErrorLine) {
  std::ostringstream out, err;
  {
    Tool tool;
    const char* argv[] = {"tool", "--help"};
    EXPECT_EQ(tool.line.ParseOrExitCode(2, argv, out, err), 0);
    EXPECT_EQ(out.str(), tool.line.Help());
    EXPECT_EQ(err.str(), "");
  }
  out.str("");
  {
    Tool tool;
    const char* argv[] = {"tool", "--bag", "a", "--seed", "1", "--fast"};
    EXPECT_EQ(tool.line.ParseOrExitCode(6, argv, out, err), 2);
    EXPECT_EQ(out.str(), "");
    EXPECT_EQ(err.str(), "tool: error: unknown argument '--fast'; " + tool.line.Usage() +
                             " (--help lists every option)\n");
  }
  {
    Tool tool;
    const char* argv[] = {"tool", "--bag", "a", "--seed", "1"};
    EXPECT_EQ(tool.line.ParseOrExitCode(5, argv, out, err), std::nullopt);
    EXPECT_EQ(tool.bag, "a");
  }
}

}  // namespace
}  // namespace ipm_road_mapper
