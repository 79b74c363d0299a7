// The text-option parser every front end goes through (atlas/core/option_schema.h),
// checked against independent readers: strtod / strtoll on the same text, and the
// kind's rule written out by hand.
#include "atlas/core/option_schema.h"

#include <gtest/gtest.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

namespace atlas {
namespace {

// Probes around the bounds of [lo, hi] plus text no number reader should take.
std::vector<std::string> number_probes(double lo, double hi) {
    std::vector<std::string> v{"", " ", "abc", "nan", "NaN", "inf", "-inf", "1e999", "0x10", "1,5", "1 2", "--1", "++1", "+-1",
                               "0", "-0", "+3", " 2.5 ", "2.7", "17", "-1", "1e3", "1e-300", "12abc"};
    for (double b : {lo, hi})
        for (double x : {b, std::nextafter(b, -INFINITY), std::nextafter(b, INFINITY), b - 1, b + 1, b - 0.5, b + 0.5}) {
            char buf[64];
            std::snprintf(buf, sizeof buf, "%.17g", x);
            v.push_back(buf);
        }
    return v;
}

std::string trimmed(const std::string& s) {
    const size_t a = s.find_first_not_of(" \t");
    return a == std::string::npos ? "" : s.substr(a, s.find_last_not_of(" \t") - a + 1);
}

// strtod reading of the kind's rule: the whole trimmed text, decimal (no hex, no
// inf/nan words), one optional sign.
bool reference_number(const std::string& text, double lo, double hi, double& out) {
    std::string s = trimmed(text);
    if (s.empty()) return false;
    for (char c : s)
        if (!(std::isdigit((unsigned char)c) || c == '.' || c == 'e' || c == 'E' || c == '-' || c == '+')) return false;
    if (s.find("0x") != std::string::npos || s.find("0X") != std::string::npos) return false;
    if (s.size() > 1 && (s[0] == '+' || s[0] == '-') && (s[1] == '+' || s[1] == '-')) return false;
    char* end = nullptr;
    errno = 0;
    out = std::strtod(s.c_str(), &end);
    // ERANGE with a non-zero result is a subnormal number: a number all the same.
    const bool representable = errno != ERANGE || (out != 0 && std::isfinite(out));
    return end == s.c_str() + s.size() && representable && std::isfinite(out) && out >= lo && out <= hi;
}

TEST(OptionSchema, NumberTakesWhatStrtodTakesInRange) {
    const TextOptionSpec o{"x", nullptr, "X", OptionKind::Number, "", 0.0, 3.4e38};
    for (const std::string& t : number_probes(o.min, o.max)) {
        OptionValue v;
        double ref = 0;
        const bool want = reference_number(t, o.min, o.max, ref);
        EXPECT_EQ(parse_text_option(o, t, v), want) << "'" << t << "'";
        if (want) {
            EXPECT_EQ(v.number, ref) << t;
        }
    }
}

TEST(OptionSchema, IntegerTakesWholeNumbersInRangeAndItsWords) {
    const TextOptionSpec o{"n", nullptr, "N", OptionKind::Integer, "", 1, 16, {"full"}};
    for (std::string t : number_probes(o.min, o.max)) {
        OptionValue v;
        const std::string s = trimmed(t);
        char* end = nullptr;
        const long long n = s.empty() ? 0 : std::strtoll(s.c_str(), &end, 10);
        const bool whole = !s.empty() && s[0] != '+' && end == s.c_str() + s.size();
        EXPECT_EQ(parse_text_option(o, t, v), whole && n >= 1 && n <= 16) << "'" << t << "'";
    }
    OptionValue v;
    EXPECT_TRUE(parse_text_option(o, "full", v));
    EXPECT_EQ(v.word, "full");
    EXPECT_FALSE(parse_text_option(o, "Full", v));
    EXPECT_EQ(o.expected(), "an integer in [1, 16] or 'full'");
}

TEST(OptionSchema, ChoiceListFlagAndRange) {
    const TextOptionSpec choice{"c", nullptr, "C", OptionKind::Choice, "", -INFINITY, INFINITY, {"a", "bb"}};
    const TextOptionSpec list{"l", nullptr, "L", OptionKind::List, "", -INFINITY, INFINITY, {"a", "bb"}};
    const TextOptionSpec names{"l", nullptr, "L", OptionKind::List, ""};
    const TextOptionSpec flag{"f", nullptr, "", OptionKind::Flag, ""};
    const TextOptionSpec range{"r", nullptr, "LO,HI", OptionKind::Range, ""};
    OptionValue v;
    for (const char* t : {"a", "bb", " a "}) EXPECT_TRUE(parse_text_option(choice, t, v)) << t;
    for (const char* t : {"", "b", "A", "a,bb"}) EXPECT_FALSE(parse_text_option(choice, t, v)) << t;
    ASSERT_TRUE(parse_text_option(list, " bb , a", v));
    EXPECT_EQ(v.items, (std::vector<std::string>{"bb", "a"}));
    for (const char* t : {"", ",", "a,", "a,,bb", "a,c"}) EXPECT_FALSE(parse_text_option(list, t, v)) << t;
    EXPECT_TRUE(parse_text_option(names, "x,y z", v));
    EXPECT_FALSE(parse_text_option(names, "x,", v));
    for (const char* t : {"true", "1", "yes", "on"}) EXPECT_TRUE(parse_text_option(flag, t, v) && v.flag) << t;
    for (const char* t : {"false", "0", "no", "off"}) EXPECT_TRUE(parse_text_option(flag, t, v) && !v.flag) << t;
    for (const char* t : {"", "2", "True", "maybe"}) EXPECT_FALSE(parse_text_option(flag, t, v)) << t;
    ASSERT_TRUE(parse_text_option(range, " -1 , 2.5", v));
    EXPECT_EQ(v.lo, -1.0);
    EXPECT_EQ(v.hi, 2.5);
    for (const char* t : {"", "1", "1,1", "2,1", "0,1,2", "nan,1", "0,inf", ",1", "0,"}) EXPECT_FALSE(parse_text_option(range, t, v)) << t;
    const TextOptionSpec bounded{"r", nullptr, "LO,HI", OptionKind::Range, "", -10, 10};
    EXPECT_TRUE(parse_text_option(bounded, "-10,10", v));
    EXPECT_FALSE(parse_text_option(bounded, "-10.5,0", v));
    EXPECT_FALSE(parse_text_option(bounded, "0,11", v));
}

// Vectors (count > 1): each part read as the scalar kind reads it, split at the
// separator by hand here (an independent reader: std::string::find + strtod).
TEST(OptionSchema, VectorsTakeCountPartsEachAsTheScalarKind) {
    TextOptionSpec three{"v", nullptr, "X,Y,Z", OptionKind::Number, "", -1, 1};
    three.count = 3;
    TextOptionSpec size{"s", nullptr, "WxH", OptionKind::Integer, "", 1, 8192};
    size.count = 2;
    size.separator = 'x';
    TextOptionSpec colour = three;
    colour.words = {"auto"};
    auto reference = [](const TextOptionSpec& o, const std::string& text, std::vector<double>& out) {
        out.clear();
        size_t start = 0;
        for (int i = 0; i < o.count; ++i) {
            const size_t at = i + 1 < o.count ? text.find(o.separator, start) : text.size();
            if (at == std::string::npos) return false;
            const std::string part = trimmed(text.substr(start, at - start));
            double x = 0;
            if (o.kind == OptionKind::Number) {
                if (!reference_number(part, o.min, o.max, x)) return false;
            } else {
                if (part.empty() || part.find_first_not_of("+-0123456789") != std::string::npos || part[0] == '+') return false;
                char* end = nullptr;
                x = double(std::strtoll(part.c_str(), &end, 10));
                if (*end != '\0' || x < o.min || x > o.max) return false;
            }
            out.push_back(x);
            start = at + 1;
        }
        return true;
    };
    const std::vector<std::string> texts{"0,0,0", " 1 , -1 ,0.5", "1,2,0", "0,0", "0,0,0,0", "0,,0", ",0,0", "0,0,", "nan,0,0", "0,0,inf",
                                         "1x1", "8192x8192", "8193x1", "0x5", "2.5x3", "-1x2", "12x", "x12", "12x34x56", " 640 x 480 ", "auto",
                                         "autox", "1e0,0,0", "+1,0,0"};
    for (const TextOptionSpec* o : {&three, &size}) {
        for (const std::string& t : texts) {
            OptionValue v;
            std::vector<double> want;
            const bool ok = reference(*o, t, want);
            EXPECT_EQ(parse_text_option(*o, t, v), ok) << o->name << " '" << t << "'";
            if (ok) {
                EXPECT_EQ(v.numbers, want) << t;
                EXPECT_EQ(v.number, want[0]) << t;
            }
        }
    }
    OptionValue v;
    EXPECT_TRUE(parse_text_option(colour, "auto", v));
    EXPECT_EQ(v.word, "auto");
    EXPECT_TRUE(v.numbers.empty());
    EXPECT_TRUE(parse_text_option(colour, "0.5,0.5,0.5", v));
    EXPECT_TRUE(v.word.empty());
    EXPECT_EQ(v.numbers.size(), 3u);
    EXPECT_FALSE(parse_text_option(three, "auto", v));
    EXPECT_EQ(three.expected(), "3 finite numbers in [-1, 1] separated by ','");
    EXPECT_EQ(size.expected(), "2 integers in [1, 8192] separated by 'x'");
    EXPECT_EQ(colour.expected(), "3 finite numbers in [-1, 1] separated by ',' or 'auto'");
    // Text: whatever check_text accepts, kept as given.
    TextOptionSpec text{"t", nullptr, "A;B", OptionKind::Text, ""};
    text.check_text = [](std::string_view s) { return s.find('!') == std::string_view::npos ? std::string() : std::string("no '!'"); };
    EXPECT_TRUE(parse_text_option(text, " a; b ", v));
    EXPECT_EQ(v.text, " a; b ");
    EXPECT_FALSE(parse_text_option(text, "a!", v));
}

// option_value_text (how a struct's own value becomes a default_text) is read back by
// the parser as the same value: numbers bit for bit, every kind.
TEST(OptionSchema, ValueTextReadsBackAsTheSameValue) {
    const TextOptionSpec number{"n", nullptr, "", OptionKind::Number, ""};
    const TextOptionSpec integer{"i", nullptr, "", OptionKind::Integer, "", -1e15, 1e15, {"full"}};
    TextOptionSpec pair{"p", nullptr, "WxH", OptionKind::Number, ""};
    pair.count = 2;
    pair.separator = 'x';
    for (double x : {0.0, -0.0, 0.1, 1e-6, 1e-12, 2.2, 1e9, 1e-310, -123.456, 4294967295.0, 1.0 / 3.0}) {
        OptionValue in, out;
        in.number = x;
        ASSERT_TRUE(parse_text_option(number, option_value_text(number, in), out)) << x;
        EXPECT_EQ(std::signbit(out.number), std::signbit(x)) << x;
        EXPECT_EQ(out.number, x) << option_value_text(number, in);
        in.numbers = {x, -x};
        ASSERT_TRUE(parse_text_option(pair, option_value_text(pair, in), out)) << x;
        EXPECT_EQ(out.numbers, in.numbers);
    }
    for (double x : {0.0, 64.0, -1.0, 1e14}) {
        OptionValue in, out;
        in.number = x;
        ASSERT_TRUE(parse_text_option(integer, option_value_text(integer, in), out)) << x;
        EXPECT_EQ(out.number, x);
    }
    OptionValue word;
    word.word = "full";
    EXPECT_EQ(option_value_text(integer, word), "full");
    const TextOptionSpec flag{"f", nullptr, "", OptionKind::Flag, ""};
    const TextOptionSpec choice{"c", nullptr, "", OptionKind::Choice, "", -INFINITY, INFINITY, {"a", "bb"}};
    const TextOptionSpec list{"l", nullptr, "", OptionKind::List, ""};
    const TextOptionSpec range{"r", nullptr, "LO,HI", OptionKind::Range, ""};
    OptionValue in, out;
    in.flag = true;
    EXPECT_TRUE(parse_text_option(flag, option_value_text(flag, in), out) && out.flag);
    in.flag = false;
    EXPECT_TRUE(parse_text_option(flag, option_value_text(flag, in), out) && !out.flag);
    in.word = "bb";
    EXPECT_TRUE(parse_text_option(choice, option_value_text(choice, in), out));
    EXPECT_EQ(out.word, "bb");
    in.items = {"x", "y"};
    EXPECT_TRUE(parse_text_option(list, option_value_text(list, in), out));
    EXPECT_EQ(out.items, in.items);
    in.lo = -0.1;
    in.hi = 2.5;
    EXPECT_TRUE(parse_text_option(range, option_value_text(range, in), out));
    EXPECT_EQ(out.lo, -0.1);
    EXPECT_EQ(out.hi, 2.5);
}

} // namespace
} // namespace atlas
