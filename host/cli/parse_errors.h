// CLI11's parse errors in the user's words: which flag, what it was given, what it takes.
#pragma once
#include <string>

namespace CLI {
class App;
class ParseError;
}  // namespace CLI

namespace fh {

// One line (without the "fredholm: error: " prefix) for a failed parse of argv by `app`.
std::string explainParseError(const CLI::App& app, const CLI::ParseError& error, int argc, char** argv);

}  // namespace fh
