#pragma once
// Private to the loaders: one whitespace-delimited token as a number, strictly
// (the whole token, locale-independent) and telling apart "not a number" from
// "a number, but not a finite float".
#include <charconv>
#include <cmath>
#include <string_view>
#include <system_error>

namespace raypack {

enum class NumberToken { Ok, NotNumber, NonFinite, OutOfRange };

inline NumberToken parse_float_token(std::string_view tok, float& out) {
    const char* b = tok.data();
    const char* e = b + tok.size();
    if (b != e && *b == '+') ++b;  // from_chars rejects a leading '+'
    if (b == e || (b != tok.data() && *b == '-')) return NumberToken::NotNumber;
    double d;
    auto r = std::from_chars(b, e, d);
    if (r.ptr != e) return NumberToken::NotNumber;
    if (r.ec == std::errc::result_out_of_range) {
        // Beyond double: long double's wider exponent tells overflow (-> inf,
        // rejected below) from underflow (-> 0, accepted).
        long double ld;
        auto rl = std::from_chars(b, e, ld);
        if (rl.ec != std::errc()) return NumberToken::OutOfRange;
        d = double(ld);
    } else if (r.ec != std::errc()) {
        return NumberToken::NotNumber;
    }
    out = float(d);
    return std::isfinite(out) ? NumberToken::Ok : NumberToken::NonFinite;
}

inline NumberToken parse_int_token(std::string_view tok, long long& out) {
    const char* b = tok.data();
    const char* e = b + tok.size();
    if (b != e && *b == '+') ++b;
    if (b == e || (b != tok.data() && *b == '-')) return NumberToken::NotNumber;
    auto r = std::from_chars(b, e, out);
    if (r.ptr != e) return NumberToken::NotNumber;
    if (r.ec == std::errc::result_out_of_range) return NumberToken::OutOfRange;
    return r.ec == std::errc() ? NumberToken::Ok : NumberToken::NotNumber;
}

}  // namespace raypack
