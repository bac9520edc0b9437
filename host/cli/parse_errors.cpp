// CLI11 (Debian 12's 2.1) words its errors for the programmer ("Could not convert: --seed =
// 4294967296", "At Most 1 required but received 3"); these rewrite each kind it raises for
// the person at the terminal. The kinds are told apart by their exception type and the
// message's shape, which the CLI tests pin.
#include "cli/parse_errors.h"

#include <CLI/CLI.hpp>

#include <regex>

namespace fh {
namespace {

// What an option's value must be, from CLI11's name for its type.
std::string expectedValue(const CLI::Option& option) {
  const std::string type = option.get_type_name();
  if (type.rfind("INT", 0) == 0) return "a whole number from -2147483648 to 2147483647";
  if (type.rfind("UINT", 0) == 0) return "a whole number, 0 or more";
  if (type.rfind("FLOAT", 0) == 0) return "a number";
  return "a value";
}

// The option of that name in the command given (`command`, or the app's own).
const CLI::Option* findOption(const CLI::App& command, const std::string& name) {
  for (const CLI::Option* option : command.get_options())
    if (option->check_name(name)) return option;
  return nullptr;
}

std::string commandList(const CLI::App& app) {
  std::string names;
  for (const CLI::App* command : app.get_subcommands({})) names += (names.empty() ? "" : ", ") + command->get_name();
  return names;
}

// The command the user named, if it is one of the app's.
const CLI::App* commandGiven(const CLI::App& app, int argc, char** argv) {
  if (argc < 2) return nullptr;
  for (const CLI::App* command : app.get_subcommands({}))
    if (command->get_name() == argv[1]) return command;
  return nullptr;
}

std::string explain(const CLI::App& app, const CLI::App& command, const CLI::ParseError& error, int argc,
                    char** argv) {
  const std::string what = error.what();
  std::smatch m;
  if (dynamic_cast<const CLI::RequiredError*>(&error) && what.find("subcommand") != std::string::npos) {
    if (argc >= 2 && argv[1][0] != '-')
      return "unknown command '" + std::string(argv[1]) + "' (use " + commandList(app) + ")";
    return "give a command: " + commandList(app);
  }
  if (std::regex_match(what, m, std::regex("Could not convert: (\\S+) = (.*)"))) {
    const CLI::Option* option = findOption(command, m[1].str());
    return m[1].str() + " '" + m[2].str() + "': expected " + (option ? expectedValue(*option) : "another value");
  }
  if (std::regex_match(what, m, std::regex("(\\S+): At Most 1 required but received (\\d+)")))
    return m[1].str() + " is given " + m[2].str() + " times; give it once";
  if (std::regex_match(what, m, std::regex("(\\S+): (\\d+) required (\\S+) missing"))) {
    const CLI::Option* option = findOption(command, m[1].str());
    return m[1].str() + " needs a value (" + (option ? expectedValue(*option) : "a value") + ")";
  }
  if (std::regex_match(what, m, std::regex("(\\S+) is required"))) {
    const CLI::Option* option = findOption(command, m[1].str());
    return "missing " + m[1].str() + (option && !option->get_description().empty()
                                          ? " (" + option->get_description() + ")" : "");
  }
  if (std::regex_match(what, m, std::regex("The following arguments? (?:was|were) not expected: (.*)"))) {
    const std::string extra = m[1].str();
    return (extra.rfind("-", 0) == 0 ? "unknown flag '" : "unexpected argument '") + extra + "'";
  }
  return what;
}

}  // namespace

std::string explainParseError(const CLI::App& app, const CLI::ParseError& error, int argc, char** argv) {
  const CLI::App* command = commandGiven(app, argc, argv);
  return explain(app, command ? *command : app, error, argc, argv) + " (see fredholm " +
         (command ? command->get_name() + " " : "") + "--help)";
}

}  // namespace fh
