#pragma once
// Subcommands of the raypack CLI and the small option parser they share.
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace raypack::app {

/// Bad command line: printed with the command name, exit status 2.
class UsageError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

struct Args {
    Args(int argc, char** argv) : tokens(argv, argv + argc) {}
    std::vector<std::string> tokens;
};

struct OptionSpec {
    std::string name;        ///< "--res"
    std::string alias;       ///< "-o", or empty
    int values = 0;          ///< how many values follow it (0 = a flag)
};

/// Options parsed against a spec; every accessor validates and throws UsageError.
class ParsedArgs {
public:
    ParsedArgs(const Args& args, const std::vector<OptionSpec>& spec, std::size_t max_positional);
    bool help() const { return help_; }
    const std::vector<std::string>& positional() const { return positional_; }
    bool has(const std::string& name) const { return options_.count(name) != 0; }
    std::string text(const std::string& name, const std::string& fallback = "") const;
    /// Integer value `index` of option `name`, which must lie in [lo, hi].
    long long integer(const std::string& name, long long fallback, long long lo, long long hi, int index = 0) const;
    /// A finite number in [lo, hi], or `fallback` when the option is absent.
    double number(const std::string& name, double fallback, double lo, double hi) const;

private:
    std::vector<std::string> positional_;
    std::map<std::string, std::vector<std::string>> options_;
    bool help_ = false;
};

int run_render(const Args& args);
int run_trace(const Args& args);
int run_info(const Args& args);
int run_gen(const Args& args);
int run_rays(const Args& args);
int run_bench(const Args& args);

}  // namespace raypack::app
