// The command line of the offline tools (map_from_bag, evaluate_map, generate_drive), parsed
// the same way for all: "--name value" and "--name=value", no abbreviations, --help / -h
// printing every option with its default (exit 0), and a bad command line (unknown option,
// missing or bad value, an option twice) reported as one line naming it plus a usage hint
// (exit 2). Built on boost::program_options, hidden behind this header; no ROS.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

namespace ipm_road_mapper {

// A bad command line; what() names the option ("unknown argument '--fast'").
struct CommandLineError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The options of one tool, each bound to a variable of the caller (see the file comment).
class CommandLine {
 public:
  // `tool` names the program in messages; `description` opens the --help text.
  CommandLine(std::string tool, std::string description);
  ~CommandLine();
  CommandLine(const CommandLine&) = delete;
  CommandLine& operator=(const CommandLine&) = delete;

  // --name <value_name>, required.
  CommandLine& Required(const std::string& name, const std::string& value_name, std::string* value,
                        const std::string& help);

  // --name <value_name>, optional: *value keeps its value when the option is absent;
  // `default_text` says in --help what that means ("none", "config/mapper.yaml of the
  // package").
  CommandLine& Optional(const std::string& name, const std::string& value_name, std::string* value,
                        const std::string& default_text, const std::string& help);

  // --name <value_name>, an integer in [lo, hi]; optional ones keep *value when absent.
  CommandLine& Integer(const std::string& name, const std::string& value_name, std::int64_t* value,
                       std::int64_t lo, std::int64_t hi, bool required,
                       const std::string& default_text, const std::string& help);

  // --name, a switch: *value becomes true when it is given (off by default).
  CommandLine& Flag(const std::string& name, bool* value, const std::string& help);

  // Parses argv into the bound variables. False when --help / -h was given (then nothing
  // else is checked and no variable is set). Throws CommandLineError.
  bool Parse(int argc, const char* const* argv);

  // "usage: <tool> --a <x> [--b <y>] [--c]", the options in the order they were added.
  std::string Usage() const;

  // Usage, description and one entry per option with its default, for --help.
  std::string Help() const;

  // The one line a bad command line prints: "<tool>: error: <message>; <usage> (--help
  // lists every option)".
  std::string ErrorLine(const std::string& message) const;

  // Parse with the tools' conventions: --help prints Help() on `out` and gives 0; a
  // CommandLineError prints ErrorLine on `err` and gives 2; otherwise nullopt (go on).
  std::optional<int> ParseOrExitCode(int argc, const char* const* argv, std::ostream& out,
                                     std::ostream& err);
  // The same on stdout / stderr.
  std::optional<int> ParseOrExitCode(int argc, const char* const* argv);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The integer in `text`, checked to lie in [lo, hi]; throws CommandLineError naming `name`.
std::int64_t ParseIntegerOption(const std::string& name, const std::string& text, std::int64_t lo,
                                std::int64_t hi);

}  // namespace ipm_road_mapper
