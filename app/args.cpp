#include <cmath>
#include <cctype>
#include <cerrno>
#include <cstdlib>

#include "app/commands.h"

namespace raypack::app {

ParsedArgs::ParsedArgs(const Args& args, const std::vector<OptionSpec>& spec, std::size_t max_positional) {
    const auto& t = args.tokens;
    for (std::size_t i = 0; i < t.size(); ++i) {
        const std::string& tok = t[i];
        if (tok == "-h" || tok == "--help") {
            help_ = true;
            continue;
        }
        if (tok.size() > 1 && tok[0] == '-' && !(std::isdigit(static_cast<unsigned char>(tok[1])) || tok[1] == '.')) {
            const OptionSpec* found = nullptr;
            for (const auto& s : spec)
                if (tok == s.name || (!s.alias.empty() && tok == s.alias)) found = &s;
            if (!found) throw UsageError("unknown option '" + tok + "' (see --help)");
            if (options_.count(found->name)) throw UsageError("option " + found->name + " given twice");
            std::vector<std::string> values;
            for (int v = 0; v < found->values; ++v) {
                if (i + 1 >= t.size())
                    throw UsageError("option " + found->name + " needs " + std::to_string(found->values) + " value(s)");
                values.push_back(t[++i]);
            }
            options_[found->name] = std::move(values);
            continue;
        }
        if (positional_.size() >= max_positional) throw UsageError("unexpected argument '" + tok + "'");
        positional_.push_back(tok);
    }
}

std::string ParsedArgs::text(const std::string& name, const std::string& fallback) const {
    const auto it = options_.find(name);
    return it == options_.end() || it->second.empty() ? fallback : it->second[0];
}

long long ParsedArgs::integer(const std::string& name, long long fallback, long long lo, long long hi, int index) const {
    const auto it = options_.find(name);
    if (it == options_.end()) return fallback;
    const std::string& s = it->second.at(std::size_t(index));
    errno = 0;
    char* end = nullptr;
    const long long v = std::strtoll(s.c_str(), &end, 10);
    if (s.empty() || *end != '\0' || errno == ERANGE)
        throw UsageError("option " + name + " expects an integer, got '" + s + "'");
    if (v < lo || v > hi)
        throw UsageError("option " + name + " must be between " + std::to_string(lo) + " and " + std::to_string(hi) +
                         ", got " + s);
    return v;
}

double ParsedArgs::number(const std::string& name, double fallback, double lo, double hi) const {
    const auto it = options_.find(name);
    if (it == options_.end()) return fallback;
    const std::string& s = it->second.at(0);
    errno = 0;
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    if (s.empty() || *end != '\0' || errno == ERANGE || !std::isfinite(v))
        throw UsageError("option " + name + " expects a finite number, got '" + s + "'");
    if (v < lo || v > hi)
        throw UsageError("option " + name + " must be between " + std::to_string(lo) + " and " + std::to_string(hi) +
                         ", got " + s);
    return v;
}

}  // namespace raypack::app
