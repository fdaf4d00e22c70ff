#include "ipm_road_mapper/pipeline/command_line.h"

#include <boost/program_options.hpp>
#include <cerrno>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <sstream>
#include <utility>
#include <vector>

namespace ipm_road_mapper {
namespace po = boost::program_options;

namespace {

constexpr const char* kPositional = "positional-arguments";  // hidden: rejected when given

// One option as the tool declared it.
struct Entry {
  enum class Kind { kString, kInteger, kFlag };
  Kind kind = Kind::kString;
  std::string name, value_name, default_text, help;
  bool required = false;
  std::string* string_value = nullptr;
  std::int64_t* integer_value = nullptr;
  std::int64_t lo = 0, hi = 0;
  bool* flag_value = nullptr;
};

// The --help text of an entry: what it is, then its default.
std::string HelpText(const Entry& e) {
  if (e.kind == Entry::Kind::kFlag) return e.help + " (default: off)";
  if (e.required) return e.help + " (required)";
  return e.help + " (default: " + e.default_text + ")";
}

// The one-line message of a boost::program_options error, naming the option.
std::string Describe(const po::error& error) {
  if (const auto* e = dynamic_cast<const po::unknown_option*>(&error)) {
    return "unknown argument '" + e->get_option_name() + "'";
  }
  if (const auto* e = dynamic_cast<const po::multiple_occurrences*>(&error)) {
    return "option " + e->get_option_name() + " given twice";
  }
  if (const auto* e = dynamic_cast<const po::invalid_command_line_syntax*>(&error)) {
    switch (e->kind()) {
      case po::invalid_syntax::missing_parameter:
        return e->get_option_name() + " needs a value";
      case po::invalid_syntax::extra_parameter:
        return e->get_option_name() + " takes no value";
      default:
        break;
    }
  }
  return error.what();
}

}  // namespace

struct CommandLine::Impl {
  std::string tool, description;
  std::vector<Entry> entries;
  po::options_description visible{"options", 100, 50};

  // Adds an entry and its program_options declaration.
  CommandLine& Add(CommandLine* self, Entry entry) {
    const std::string shown = entry.kind == Entry::Kind::kFlag ? "" : entry.value_name;
    if (entry.kind == Entry::Kind::kFlag) {
      visible.add_options()(entry.name.c_str(), po::bool_switch(), HelpText(entry).c_str());
    } else {
      visible.add_options()(entry.name.c_str(), po::value<std::string>()->value_name(shown),
                            HelpText(entry).c_str());
    }
    entries.push_back(std::move(entry));
    return *self;
  }
};

CommandLine::CommandLine(std::string tool, std::string description)
    : impl_(std::make_unique<Impl>()) {
  impl_->tool = std::move(tool);
  impl_->description = std::move(description);
  impl_->visible.add_options()("help,h", "print this help and exit");
}

CommandLine::~CommandLine() = default;

CommandLine& CommandLine::Required(const std::string& name, const std::string& value_name,
                                   std::string* value, const std::string& help) {
  Entry e;
  e.name = name;
  e.value_name = value_name;
  e.help = help;
  e.required = true;
  e.string_value = value;
  return impl_->Add(this, std::move(e));
}

CommandLine& CommandLine::Optional(const std::string& name, const std::string& value_name,
                                   std::string* value, const std::string& default_text,
                                   const std::string& help) {
  Entry e;
  e.name = name;
  e.value_name = value_name;
  e.default_text = default_text;
  e.help = help;
  e.string_value = value;
  return impl_->Add(this, std::move(e));
}

CommandLine& CommandLine::Integer(const std::string& name, const std::string& value_name,
                                  std::int64_t* value, std::int64_t lo, std::int64_t hi,
                                  bool required, const std::string& default_text,
                                  const std::string& help) {
  Entry e;
  e.kind = Entry::Kind::kInteger;
  e.name = name;
  e.value_name = value_name;
  e.default_text = default_text;
  e.help = help;
  e.required = required;
  e.integer_value = value;
  e.lo = lo;
  e.hi = hi;
  return impl_->Add(this, std::move(e));
}

CommandLine& CommandLine::Flag(const std::string& name, bool* value, const std::string& help) {
  Entry e;
  e.kind = Entry::Kind::kFlag;
  e.name = name;
  e.help = help;
  e.flag_value = value;
  return impl_->Add(this, std::move(e));
}

bool CommandLine::Parse(int argc, const char* const* argv) {
  po::options_description all;
  all.add(impl_->visible);
  all.add_options()(kPositional, po::value<std::vector<std::string>>());
  po::positional_options_description positional;
  positional.add(kPositional, -1);
  po::variables_map values;
  try {
    // No abbreviations: "--conf" must not silently mean "--config".
    const int style =
        po::command_line_style::default_style & ~po::command_line_style::allow_guessing;
    po::store(
        po::command_line_parser(argc, argv).options(all).positional(positional).style(style).run(),
        values);
  } catch (const po::error& e) {
    throw CommandLineError(Describe(e));
  }
  if (values.count("help")) return false;
  if (values.count(kPositional)) {
    throw CommandLineError("unexpected argument '" +
                           values[kPositional].as<std::vector<std::string>>().front() + "'");
  }
  for (const Entry& e : impl_->entries) {
    const std::string option = "--" + e.name;
    if (e.kind == Entry::Kind::kFlag) {
      if (values[e.name].as<bool>()) *e.flag_value = true;
      continue;
    }
    if (!values.count(e.name)) {
      if (e.required) throw CommandLineError("missing " + option);
      continue;
    }
    const std::string& text = values[e.name].as<std::string>();
    if (e.kind == Entry::Kind::kInteger) {
      *e.integer_value = ParseIntegerOption(option, text, e.lo, e.hi);
    } else {
      *e.string_value = text;
    }
  }
  return true;
}

std::string CommandLine::Usage() const {
  std::string usage = "usage: " + impl_->tool;
  for (const Entry& e : impl_->entries) {
    std::string item = "--" + e.name;
    if (e.kind != Entry::Kind::kFlag) item += " " + e.value_name;
    usage += e.required ? " " + item : " [" + item + "]";
  }
  return usage;
}

std::string CommandLine::Help() const {
  std::ostringstream help;
  help << Usage() << "\n\n" << impl_->description << "\n\n" << impl_->visible;
  return help.str();
}

std::string CommandLine::ErrorLine(const std::string& message) const {
  return impl_->tool + ": error: " + message + "; " + Usage() + " (--help lists every option)";
}

std::optional<int> CommandLine::ParseOrExitCode(int argc, const char* const* argv,
                                                std::ostream& out, std::ostream& err) {
  try {
    if (Parse(argc, argv)) return std::nullopt;
    out << Help();
    return 0;
  } catch (const CommandLineError& e) {
    err << ErrorLine(e.what()) << "\n";
    return 2;
  }
}

std::optional<int> CommandLine::ParseOrExitCode(int argc, const char* const* argv) {
  return ParseOrExitCode(argc, argv, std::cout, std::cerr);
}

std::int64_t ParseIntegerOption(const std::string& name, const std::string& text, std::int64_t lo,
                                std::int64_t hi) {
  errno = 0;
  char* end = nullptr;
  const long long value = std::strtoll(text.c_str(), &end, 10);
  const bool valid = !text.empty() && *end == '\0' && errno == 0 && value >= lo && value <= hi;
  if (!valid) {
    const std::string range = hi == std::numeric_limits<std::int64_t>::max()
                                  ? ">= " + std::to_string(lo)
                                  : "in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
    throw CommandLineError(name + ": expected an integer " + range + ", got '" + text + "'");
  }
  return value;
}

}  // namespace ipm_road_mapper
