#include "strata/io/svg_io.h"

#include <tinyxml2.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <glm/geometric.hpp>
#include <initializer_list>
#include <limits>
#include <optional>
#include <unordered_map>
#include <utility>
#include <vector>

#include "geometry/detail/utf8.h"
#include "strata/core/error.h"
#include "strata/core/format.h"
#include "strata/io/atomic_file.h"

namespace strata {

namespace {

constexpr double kPi = 3.14159265358979323846;
// Caps on flattening (a tolerance tiny next to the curve would otherwise never end):
// 2^20 pieces per curve at most.
constexpr int kMaxBezierDepth = 20;
constexpr double kMaxArcSegments = 1048576.0;

// ---------------------------------------------------------------------------------------------
// Messages

// Where an element is, for messages: "file.svg:12: <path id='x'>: ".
struct Origin {
    std::string source;
    int line = 0;
    std::string element;

    std::string prefix() const {
        return source + ":" + std::to_string(line) + ": " + element + ": ";
    }
};

[[noreturn]] void fail(const Origin& origin, const std::string& what) {
    throw InvalidInput(origin.prefix() + what);
}

// `text` shortened and shown safely for a message.
std::string excerpt(std::string_view text, std::size_t max_chars = 40) {
    return shown_text(text, max_chars);
}

// ---------------------------------------------------------------------------------------------
// Names that XML cannot hold. XML 1.0 has no place for a C0 control other than tab, newline and
// return, nor for bytes of no UTF-8 character (not even as a reference such as &#27;). A
// document holding such a name (an id, a name of data-outer, the units) is written with every
// name as shown_text() shows it (\xNN, a backslash as \\) and this root attribute, by which the
// reader turns them back.

constexpr const char* kNamesAttribute = "data-strata-names";
constexpr const char* kEscapedNames = "escaped";

// Length of the character at the start of `text` when it is one XML 1.0 allows, else 0.
std::size_t xml_char_length(std::string_view text) {
    const auto lead = static_cast<unsigned char>(text[0]);
    if (lead < 0x80) return lead >= 0x20 || lead == '\t' || lead == '\n' || lead == '\r' ? 1 : 0;
    const detail::Utf8Char c = detail::utf8_char(text);
    return c.code == 0xfffe || c.code == 0xffff ? 0 : c.length;
}

// True when XML can hold `text` (escaped as markup needs).
bool is_xml_text(std::string_view text) {
    for (std::size_t i = 0; i < text.size();) {
        const std::size_t n = xml_char_length(text.substr(i));
        if (n == 0) return false;
        i += n;
    }
    return true;
}

// shown_text() undone: \\ a backslash, \xNN the byte NN; any other backslash kept as it is.
std::string unshown_text(std::string_view text) {
    const auto hex = [](char c) {
        return c >= '0' && c <= '9'   ? c - '0'
               : c >= 'a' && c <= 'f' ? c - 'a' + 10
               : c >= 'A' && c <= 'F' ? c - 'A' + 10
                                      : -1;
    };
    std::string out;
    out.reserve(text.size());
    for (std::size_t i = 0; i < text.size(); ++i) {
        if (text[i] == '\\' && i + 1 < text.size() && text[i + 1] == '\\') {
            out += '\\';
            ++i;
        } else if (text[i] == '\\' && i + 3 < text.size() && text[i + 1] == 'x' &&
                   hex(text[i + 2]) >= 0 && hex(text[i + 3]) >= 0) {
            out += static_cast<char>(hex(text[i + 2]) * 16 + hex(text[i + 3]));
            i += 3;
        } else {
            out += text[i];
        }
    }
    return out;
}

// ---------------------------------------------------------------------------------------------
// Affine maps, SVG's matrix(a b c d e f): x' = a x + c y + e, y' = b x + d y + f.

struct Affine {
    double a = 1.0, b = 0.0, c = 0.0, d = 1.0, e = 0.0, f = 0.0;

    bool is_identity() const {
        return a == 1.0 && b == 0.0 && c == 0.0 && d == 1.0 && e == 0.0 && f == 0.0;
    }
    Vec2 apply(const Vec2& p) const { return {a * p.x + c * p.y + e, b * p.x + d * p.y + f}; }
    Vec2 apply_linear(const Vec2& v) const { return {a * v.x + c * v.y, b * v.x + d * v.y}; }
};

// m * n: n is applied first.
Affine compose(const Affine& m, const Affine& n) {
    return {m.a * n.a + m.c * n.b, m.b * n.a + m.d * n.b,       m.a * n.c + m.c * n.d,
            m.b * n.c + m.d * n.d, m.a * n.e + m.c * n.f + m.e, m.b * n.e + m.d * n.f + m.f};
}

// Cosine and sine of an angle in degrees, exact at multiples of 90 degrees.
std::pair<double, double> cos_sin_degrees(double degrees) {
    const double reduced = std::fmod(degrees, 360.0);
    const double quarter = reduced / 90.0;
    if (quarter == std::floor(quarter)) {
        switch ((static_cast<int>(quarter) % 4 + 4) % 4) {
            case 0:
                return {1.0, 0.0};
            case 1:
                return {0.0, 1.0};
            case 2:
                return {-1.0, 0.0};
            default:
                return {0.0, -1.0};
        }
    }
    const double radians = reduced * kPi / 180.0;
    return {std::cos(radians), std::sin(radians)};
}

// From SVG user space (after the element's transforms) to scene coordinates: y flipped.
struct OutputMap {
    Affine svg;  // element and ancestors' transforms
    bool is_identity = true;

    explicit OutputMap(const Affine& m) : svg(m), is_identity(m.is_identity()) {}
    Vec2 operator()(const Vec2& p) const {
        if (is_identity) return {p.x, -p.y};
        const Vec2 q = svg.apply(p);
        return {q.x, -q.y};
    }
};

// ---------------------------------------------------------------------------------------------
// Numbers (SVG grammar: sign? (digits ("." digits?)? | "." digits) ([eE] sign? digits)?)

bool is_space(char c) {
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f';
}
bool is_digit(char c) {
    return c >= '0' && c <= '9';
}

class Scanner {
  public:
    explicit Scanner(std::string_view text) : text_(text) {}

    std::size_t pos() const { return pos_; }
    bool at_end() const { return pos_ >= text_.size(); }
    char peek() const { return at_end() ? '\0' : text_[pos_]; }
    void advance() { ++pos_; }

    void skip_space() {
        while (!at_end() && is_space(text_[pos_])) ++pos_;
    }
    // wsp* ","? wsp*; true when a comma was skipped.
    bool skip_comma_space() {
        skip_space();
        if (peek() != ',') return false;
        ++pos_;
        skip_space();
        return true;
    }
    bool at_number() const {
        const char c = peek();
        return is_digit(c) || c == '.' || c == '-' || c == '+';
    }

    // The number at the current position; nothing (position unchanged) when there is none
    // or it overflows a double.
    std::optional<double> number() {
        out_of_range_ = false;
        if (at_end()) return std::nullopt;
        const std::size_t start = pos_;
        std::size_t i = pos_;
        auto digits = [&] {
            const std::size_t from = i;
            while (i < text_.size() && is_digit(text_[i])) ++i;
            return i - from;
        };
        if (i < text_.size() && (text_[i] == '+' || text_[i] == '-')) ++i;
        const std::size_t first = text_[start] == '+' ? start + 1 : start;  // from_chars: no '+'
        std::size_t mantissa = digits();
        if (i < text_.size() && text_[i] == '.') {
            ++i;
            mantissa += digits();
        }
        if (mantissa == 0) return std::nullopt;
        if (i < text_.size() && (text_[i] == 'e' || text_[i] == 'E')) {
            std::size_t j = i + 1;
            if (j < text_.size() && (text_[j] == '+' || text_[j] == '-')) ++j;
            if (j < text_.size() && is_digit(text_[j])) {
                i = j;
                digits();
            }
        }
        double value = 0.0;
        const char* begin = text_.data() + first;
        const char* end = text_.data() + i;
        const auto [ptr, ec] = std::from_chars(begin, end, value);
        if (ec != std::errc() || ptr != end || !std::isfinite(value)) {
            out_of_range_ = true;
            return std::nullopt;
        }
        pos_ = i;
        return value;
    }

    // True when the last number() failed on a well-formed number too large for a double.
    bool out_of_range() const { return out_of_range_; }

    // An arc flag: a single '0' or '1' (no separator needed after it).
    std::optional<bool> flag() {
        const char c = peek();
        if (c != '0' && c != '1') return std::nullopt;
        ++pos_;
        return c == '1';
    }

  private:
    std::string_view text_;
    std::size_t pos_ = 0;
    bool out_of_range_ = false;
};

std::string_view trim(std::string_view s) {
    while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
    while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
    return s;
}

// The whole of `text` as one number, or nothing.
std::optional<double> parse_single_number(std::string_view text) {
    const std::string_view t = trim(text);
    if (t.empty()) return std::nullopt;
    Scanner scanner(t);
    const std::optional<double> value = scanner.number();
    if (!value || !scanner.at_end()) return std::nullopt;
    return value;
}

// A list of numbers separated by commas and/or whitespace (the `points` attribute).
std::vector<double> parse_number_list(std::string_view text, const Origin& origin,
                                      const char* attribute) {
    std::vector<double> values;
    Scanner scanner(text);
    scanner.skip_space();
    while (!scanner.at_end()) {
        const std::optional<double> value = scanner.number();
        if (!value)
            fail(origin, std::string(attribute) + ": bad number near '" +
                             excerpt(text.substr(scanner.pos()), 16) + "' in " + attribute + "='" +
                             excerpt(text) + "'");
        values.push_back(*value);
        scanner.skip_comma_space();
    }
    return values;
}

// ---------------------------------------------------------------------------------------------
// transform="..."

Affine parse_transform(std::string_view text, const Origin& origin) {
    Affine result;
    Scanner s(text);
    std::size_t item_start = 0;
    auto bad = [&](const std::string& why) {
        fail(origin, "transform: bad transform near '" + excerpt(text.substr(item_start), 24) +
                         "' in transform='" + excerpt(text) + "' (" + why + ")");
    };
    for (;;) {
        s.skip_comma_space();
        if (s.at_end()) break;
        const std::size_t name_start = item_start = s.pos();
        while (!s.at_end() && std::isalpha(static_cast<unsigned char>(s.peek()))) s.advance();
        const std::string name(text.substr(name_start, s.pos() - name_start));
        if (name.empty()) bad("expected a transform function");
        s.skip_space();
        if (s.peek() != '(') bad("expected '(' after " + name);
        s.advance();
        std::vector<double> args;
        s.skip_space();
        while (s.peek() != ')') {
            if (!args.empty()) s.skip_comma_space();
            const std::optional<double> value = s.number();
            if (!value) bad("expected a number or ')' in " + name);
            args.push_back(*value);
            s.skip_space();
        }
        s.advance();
        const std::size_t n = args.size();
        auto need = [&](std::initializer_list<std::size_t> counts) {
            if (std::find(counts.begin(), counts.end(), n) == counts.end())
                bad(name + " takes " + std::to_string(*counts.begin()) +
                    (counts.size() > 1 ? " or " + std::to_string(*(counts.end() - 1)) : "") +
                    " numbers, got " + std::to_string(n));
        };
        Affine m;
        if (name == "matrix") {
            need({6});
            m = {args[0], args[1], args[2], args[3], args[4], args[5]};
        } else if (name == "translate") {
            need({1, 2});
            m.e = args[0];
            m.f = n == 2 ? args[1] : 0.0;
        } else if (name == "scale") {
            need({1, 2});
            m.a = args[0];
            m.d = n == 2 ? args[1] : args[0];
        } else if (name == "rotate") {
            need({1, 3});
            const auto [cos_a, sin_a] = cos_sin_degrees(args[0]);
            m = {cos_a, sin_a, -sin_a, cos_a, 0.0, 0.0};
            if (n == 3) {
                const Affine to{1.0, 0.0, 0.0, 1.0, args[1], args[2]};
                const Affine back{1.0, 0.0, 0.0, 1.0, -args[1], -args[2]};
                m = compose(to, compose(m, back));
            }
        } else if (name == "skewX" || name == "skewY") {
            need({1});
            const auto [cos_a, sin_a] = cos_sin_degrees(args[0]);
            if (cos_a == 0.0) bad(name + " of " + format_number(args[0]) + " degrees");
            (name == "skewX" ? m.c : m.b) = sin_a / cos_a;
        } else {
            bad("unknown function '" + excerpt(name) + "'");
        }
        result = compose(result, m);
    }
    return result;
}

// ---------------------------------------------------------------------------------------------
// Flattening (in scene coordinates, which are SVG user space after transforms, y flipped:
// an isometry, so tolerances carry over).

// Appends the flattened cubic p0..p3 without p0; ends exactly at p3. Stops splitting when
// the control points are within `tol` of their places on the chord, which bounds the
// distance between the curve and the chord (convex hull of the difference curve).
void flatten_cubic(const Vec2& p0, const Vec2& p1, const Vec2& p2, const Vec2& p3, double tol,
                   int depth, std::vector<Vec2>& out) {
    const double d1 = glm::length(p1 - (2.0 * p0 + p3) / 3.0);
    const double d2 = glm::length(p2 - (p0 + 2.0 * p3) / 3.0);
    if ((d1 <= tol && d2 <= tol) || depth >= kMaxBezierDepth) {
        out.push_back(p3);
        return;
    }
    const Vec2 p01 = 0.5 * (p0 + p1), p12 = 0.5 * (p1 + p2), p23 = 0.5 * (p2 + p3);
    const Vec2 p012 = 0.5 * (p01 + p12), p123 = 0.5 * (p12 + p23);
    const Vec2 mid = 0.5 * (p012 + p123);
    flatten_cubic(p0, p01, p012, mid, tol, depth + 1, out);
    flatten_cubic(mid, p123, p23, p3, tol, depth + 1, out);
}

struct Subpath {
    std::vector<Vec2> points;  // scene coordinates
    bool closed = false;
    bool has_segments = false;
};

// Builds subpaths from drawing commands given in the element's local coordinates.
class PathBuilder {
  public:
    // `curve_points`: vertices made by flattening so far in the document, at most
    // `max_curve_points` (else InvalidInput at `origin`).
    PathBuilder(const OutputMap& map, double tolerance, std::size_t& curve_points,
                std::size_t max_curve_points, const Origin& origin)
        : map_(map),
          tol_(tolerance),
          curve_points_(curve_points),
          max_curve_points_(max_curve_points),
          origin_(origin) {}

    void move_to(const Vec2& p) {
        flush();
        current_ = {};
        current_.points.push_back(map_(p));
    }
    void line_to(const Vec2& p) {
        current_.points.push_back(map_(p));
        current_.has_segments = true;
    }
    // Cubic from the current point; the control points and `to` are local.
    void cubic_to(const Vec2& c1, const Vec2& c2, const Vec2& to) {
        const Vec2 from = current_.points.back();
        const std::size_t before = current_.points.size();
        flatten_cubic(from, map_(c1), map_(c2), map_(to), tol_, 0, current_.points);
        count_curve_points(current_.points.size() - before);
        current_.has_segments = true;
    }
    // Quadratic from `from` (the local current point), raised to a cubic.
    void quad_to(const Vec2& from, const Vec2& c, const Vec2& to) {
        cubic_to(from + (2.0 / 3.0) * (c - from), to + (2.0 / 3.0) * (c - to), to);
    }
    // SVG arc from `from` to `to` (implementation notes F.6.5, F.6.6 of SVG 1.1).
    void arc_to(const Vec2& from, double rx, double ry, double phi_degrees, bool large_arc,
                bool sweep, const Vec2& to) {
        if (from == to) return;  // the segment is omitted
        rx = std::abs(rx);
        ry = std::abs(ry);
        if (rx == 0.0 || ry == 0.0) {
            line_to(to);
            return;
        }
        const auto [cos_phi, sin_phi] = cos_sin_degrees(phi_degrees);
        const Vec2 half = 0.5 * (from - to);
        const double x1 = cos_phi * half.x + sin_phi * half.y;
        const double y1 = -sin_phi * half.x + cos_phi * half.y;
        const double lambda = (x1 * x1) / (rx * rx) + (y1 * y1) / (ry * ry);
        if (lambda > 1.0) {
            rx *= std::sqrt(lambda);
            ry *= std::sqrt(lambda);
        }
        const double rx2 = rx * rx, ry2 = ry * ry;
        const double den = rx2 * y1 * y1 + ry2 * x1 * x1;
        double coef = std::sqrt(std::max(0.0, (rx2 * ry2 - den) / den));
        if (large_arc == sweep) coef = -coef;
        const double cx1 = coef * rx * y1 / ry;
        const double cy1 = -coef * ry * x1 / rx;
        const Vec2 center(cos_phi * cx1 - sin_phi * cy1 + 0.5 * (from.x + to.x),
                          sin_phi * cx1 + cos_phi * cy1 + 0.5 * (from.y + to.y));
        const Vec2 u((x1 - cx1) / rx, (y1 - cy1) / ry);
        const Vec2 v((-x1 - cx1) / rx, (-y1 - cy1) / ry);
        const double theta1 = std::atan2(u.y, u.x);
        double dtheta = std::atan2(u.x * v.y - u.y * v.x, u.x * v.x + u.y * v.y);
        if (!sweep && dtheta > 0.0) dtheta -= 2.0 * kPi;
        if (sweep && dtheta < 0.0) dtheta += 2.0 * kPi;

        // Piece of half-angle h: the arc stays within s (1 - cos h + h^3 / 6) <=
        // s h^2 / 2 (1 + h / 3) of its chord, s the Frobenius norm of the ellipse's matrix
        // in scene coordinates (>= its largest semi-axis).
        const Vec2 axis_u = map_.svg.apply_linear(Vec2(rx * cos_phi, rx * sin_phi));
        const Vec2 axis_v = map_.svg.apply_linear(Vec2(-ry * sin_phi, ry * cos_phi));
        const double s = std::sqrt(glm::dot(axis_u, axis_u) + glm::dot(axis_v, axis_v));
        const double h0 = std::sqrt(2.0 * tol_ / s);
        const double h = std::min(kPi / 4.0, h0 / std::sqrt(1.0 + h0 / 3.0));
        const double pieces = std::min(kMaxArcSegments, std::ceil(std::abs(dtheta) / (2.0 * h)));
        const std::size_t n = std::max<std::size_t>(1, static_cast<std::size_t>(pieces));
        count_curve_points(n - 1);
        for (std::size_t i = 1; i < n; ++i) {
            const double t = theta1 + dtheta * static_cast<double>(i) / static_cast<double>(n);
            const Vec2 local(rx * std::cos(t), ry * std::sin(t));
            current_.points.push_back(map_(center + Vec2(cos_phi * local.x - sin_phi * local.y,
                                                         sin_phi * local.x + cos_phi * local.y)));
        }
        line_to(to);
    }
    // Z: closes the subpath; a drawing command after it starts a new one at `start`.
    void close(const Vec2& start) {
        current_.closed = true;
        flush();
        current_ = {};
        current_.points.push_back(map_(start));
    }

    std::vector<Subpath> finish() {
        flush();
        current_ = {};
        return std::move(done_);
    }

  private:
    void count_curve_points(std::size_t added) {
        curve_points_ += added;
        if (curve_points_ > max_curve_points_)
            fail(origin_, "flattening the curves and arcs takes more than " +
                              std::to_string(max_curve_points_) +
                              " vertices in the document (curves far larger than the flatten "
                              "tolerance " +
                              format_number(tol_) + ")");
    }

    void flush() {
        if (!current_.has_segments) return;
        if (current_.closed)  // Z draws the closing segment: a repeated first point is dropped
            while (current_.points.size() > 1 && current_.points.back() == current_.points.front())
                current_.points.pop_back();
        done_.push_back(std::move(current_));
        current_ = {};
    }

    OutputMap map_;
    double tol_;
    std::size_t& curve_points_;
    std::size_t max_curve_points_;
    const Origin& origin_;
    Subpath current_;
    std::vector<Subpath> done_;
};

// ---------------------------------------------------------------------------------------------
// d="..."

bool is_command(char c) {
    return std::strchr("MmLlHhVvZzCcSsQqTtAa", c) != nullptr && c != '\0';
}

std::size_t argument_count(char upper) {
    switch (upper) {
        case 'M':
        case 'L':
        case 'T':
            return 2;
        case 'H':
        case 'V':
            return 1;
        case 'C':
            return 6;
        case 'S':
        case 'Q':
            return 4;
        case 'A':
            return 7;
        default:
            return 0;
    }
}

std::vector<Subpath> parse_path_data(std::string_view d, const OutputMap& map, double tolerance,
                                     std::size_t& curve_points, std::size_t max_curve_points,
                                     const Origin& origin) {
    PathBuilder builder(map, tolerance, curve_points, max_curve_points, origin);
    Scanner s(d);
    std::size_t group_start = 0;
    auto bad = [&](const std::string& why) {
        std::size_t end = s.pos();  // through the offending token
        while (end < d.size() && !is_space(d[end]) && d[end] != ',' && end - s.pos() < 16) ++end;
        end = std::min(d.size(), std::max(end, group_start + 1));
        std::string_view near = d.substr(group_start, end - group_start);
        if (near.size() > 40) near = near.substr(near.size() - 40);
        fail(origin, "d: bad path data near '" + excerpt(trim(near)) + "' (" + why + ")");
    };

    Vec2 current(0.0), start(0.0), last_cubic(0.0), last_quad(0.0);
    char previous = 0;  // upper-case letter of the previous segment
    bool first = true;
    s.skip_space();
    while (!s.at_end()) {
        group_start = s.pos();
        char command = s.peek();
        if (!is_command(command)) bad("expected a command letter");
        s.advance();
        if (first && command != 'M' && command != 'm') bad("path data must start with M or m");
        first = false;
        const char upper = static_cast<char>(std::toupper(static_cast<unsigned char>(command)));
        if (upper == 'Z') {
            builder.close(start);
            current = start;
            previous = 'Z';
            s.skip_space();
            continue;
        }
        const bool relative = command != upper;
        const std::size_t count = argument_count(upper);
        bool repeat = false;
        do {
            std::array<double, 7> a{};
            for (std::size_t i = 0; i < count; ++i) {
                if (i > 0 || repeat)
                    s.skip_comma_space();
                else
                    s.skip_space();
                if (upper == 'A' && (i == 3 || i == 4)) {
                    const std::optional<bool> value = s.flag();
                    if (!value)
                        bad(std::string("arc flag ") + (i == 3 ? "large-arc" : "sweep") +
                            " must be 0 or 1");
                    a[i] = *value ? 1.0 : 0.0;
                } else {
                    const std::optional<double> value = s.number();
                    if (!value && s.out_of_range()) bad("number out of range");
                    if (!value)
                        bad(std::string("'") + command + "' needs " + std::to_string(count) +
                            " numbers, found " + std::to_string(i));
                    a[i] = *value;
                }
            }
            const Vec2 base = relative ? current : Vec2(0.0);
            auto point = [&](std::size_t i) { return base + Vec2(a[i], a[i + 1]); };
            switch (upper) {
                case 'M':
                    if (!repeat) {
                        current = start = point(0);
                        builder.move_to(current);
                    } else {
                        current = point(0);
                        builder.line_to(current);
                    }
                    break;
                case 'L':
                    current = point(0);
                    builder.line_to(current);
                    break;
                case 'H':
                    current.x = base.x + a[0];
                    builder.line_to(current);
                    break;
                case 'V':
                    current.y = base.y + a[0];
                    builder.line_to(current);
                    break;
                case 'C': {
                    const Vec2 c1 = point(0), c2 = point(2), to = point(4);
                    builder.cubic_to(c1, c2, to);
                    last_cubic = c2;
                    current = to;
                    break;
                }
                case 'S': {
                    const Vec2 c1 =
                        (previous == 'C' || previous == 'S') ? 2.0 * current - last_cubic : current;
                    const Vec2 c2 = point(0), to = point(2);
                    builder.cubic_to(c1, c2, to);
                    last_cubic = c2;
                    current = to;
                    break;
                }
                case 'Q': {
                    const Vec2 c = point(0), to = point(2);
                    builder.quad_to(current, c, to);
                    last_quad = c;
                    current = to;
                    break;
                }
                case 'T': {
                    const Vec2 c =
                        (previous == 'Q' || previous == 'T') ? 2.0 * current - last_quad : current;
                    const Vec2 to = point(0);
                    builder.quad_to(current, c, to);
                    last_quad = c;
                    current = to;
                    break;
                }
                case 'A': {
                    const Vec2 to = point(5);
                    builder.arc_to(current, a[0], a[1], a[2], a[3] != 0.0, a[4] != 0.0, to);
                    current = to;
                    break;
                }
                default:
                    break;
            }
            previous = (upper == 'M' && repeat) ? 'L' : upper;
            repeat = true;
            const std::size_t before = s.pos();
            const bool comma = s.skip_comma_space();
            if (comma && !s.at_number()) bad("a comma must be followed by a number");
            if (s.at_number()) group_start = before;
        } while (s.at_number());
    }
    return builder.finish();
}

// ---------------------------------------------------------------------------------------------
// Reading the document

std::string_view local_name(const char* name) {
    std::string_view n(name ? name : "");
    const std::size_t colon = n.find(':');
    return colon == std::string_view::npos ? n : n.substr(colon + 1);
}

bool is_skipped_container(std::string_view name) {
    return name == "defs" || name == "clipPath" || name == "mask" || name == "symbol" ||
           name == "marker" || name == "pattern";
}

bool is_container(std::string_view name) {
    return name == "g" || name == "svg" || name == "a" || name == "switch";
}

class SvgReader {
  public:
    // `escaped_names`: the document's names are written as shown_text() shows them.
    SvgReader(const std::string& source, const SvgReadParams& params, bool escaped_names)
        : source_(source), params_(params), escaped_names_(escaped_names) {}

    // A name as the document writes it, as the scene holds it.
    std::string name_of(std::string_view written) const {
        return escaped_names_ ? unshown_text(written) : std::string(written);
    }

    void walk(const tinyxml2::XMLElement* parent, const Affine& transform) {
        for (const tinyxml2::XMLElement* e = parent->FirstChildElement(); e;
             e = e->NextSiblingElement()) {
            const std::string_view name = local_name(e->Name());
            if (is_skipped_container(name)) continue;
            const char* role = e->Attribute("data-strata-role");
            if (role && std::string_view(role) != "layer") continue;
            const Origin origin = origin_of(e, name);
            Affine m = transform;
            if (const char* t = e->Attribute("transform"))
                m = compose(m, parse_transform(t, origin));
            if (is_container(name))
                walk(e, m);
            else
                read_shape(e, name, m, origin);
        }
    }

    Scene finish(std::string units) {
        if (layers_.empty())
            throw InvalidInput(source_ +
                               ": nothing to read: no <path>, <polyline>, <polygon>, "
                               "<line>, <rect>, <circle> or <ellipse> with points (outside "
                               "<defs> and the like)");
        std::unordered_map<std::string, std::size_t> index;
        for (std::size_t i = 0; i < layers_.size(); ++i) {
            const auto [it, inserted] = index.emplace(layers_[i].name, i);
            if (!inserted)
                fail(origins_[i], "layer name '" + excerpt(layers_[i].name) +
                                      "' is already used by " + origins_[it->second].element +
                                      " at line " + std::to_string(origins_[it->second].line));
        }
        if (any_outer_) {
            for (std::size_t i = 0; i < layers_.size(); ++i) {
                Layer& layer = layers_[i];
                if (!layer.outer) layer.outer.emplace();
                for (const std::string& name : *layer.outer)
                    if (index.find(name) == index.end())
                        fail(origins_[i], "data-outer names '" + excerpt(name) +
                                              "', which is not a layer of the file");
            }
        }
        try {
            return Scene(std::move(layers_), std::move(units));
        } catch (const InvalidInput& e) {
            throw InvalidInput(source_ + ": " + e.what());
        }
    }

  private:
    Origin origin_of(const tinyxml2::XMLElement* e, std::string_view name) const {
        std::string element = "<" + std::string(name);
        if (const char* id = e->Attribute("id")) element += " id='" + excerpt(id) + "'";
        element += ">";
        return {source_, e->GetLineNum(), element};
    }

    // A number attribute; `fallback` when absent.
    static double number_attribute(const tinyxml2::XMLElement* e, const char* attribute,
                                   double fallback, const Origin& origin) {
        const char* text = e->Attribute(attribute);
        if (!text) return fallback;
        const std::optional<double> value = parse_single_number(text);
        if (!value)
            fail(origin, std::string(attribute) + "='" + excerpt(text) + "' is not a number");
        return *value;
    }

    std::vector<Subpath> shape_subpaths(const tinyxml2::XMLElement* e, std::string_view name,
                                        const OutputMap& map, const Origin& origin) {
        auto num = [&](const char* attribute) {
            return number_attribute(e, attribute, 0.0, origin);
        };
        auto path = [&](const std::string& d) {
            return parse_path_data(d, map, params_.flatten_tolerance, curve_points_,
                                   params_.max_curve_points, origin);
        };
        auto fmt = [](double v) { return format_number(v); };
        if (name == "path") {
            const char* d = e->Attribute("d");
            return d ? path(d) : std::vector<Subpath>{};
        }
        if (name == "polyline" || name == "polygon") {
            const char* text = e->Attribute("points");
            if (!text) return {};
            const std::vector<double> values = parse_number_list(text, origin, "points");
            if (values.size() % 2 != 0)
                fail(origin, "points has an odd number of coordinates (" +
                                 std::to_string(values.size()) + ") in points='" + excerpt(text) +
                                 "'");
            if (values.empty()) return {};
            Subpath sub;
            sub.closed = name == "polygon";
            sub.has_segments = true;
            for (std::size_t i = 0; i + 1 < values.size(); i += 2)
                sub.points.push_back(map(Vec2(values[i], values[i + 1])));
            return {sub};
        }
        if (name == "line") {
            Subpath sub;
            sub.has_segments = true;
            sub.points = {map(Vec2(num("x1"), num("y1"))), map(Vec2(num("x2"), num("y2")))};
            return {sub};
        }
        auto non_negative = [&](const char* attribute, double value) {
            if (value < 0.0)
                fail(origin, std::string(attribute) + "='" + fmt(value) + "' must be >= 0");
            return value;
        };
        if (name == "rect") {
            const double x = num("x"), y = num("y");
            const double w = non_negative("width", num("width"));
            const double h = non_negative("height", num("height"));
            if (w == 0.0 || h == 0.0) return {};
            const char* rx_text = e->Attribute("rx");
            const char* ry_text = e->Attribute("ry");
            double rx = non_negative("rx", num("rx")), ry = non_negative("ry", num("ry"));
            if (rx_text && !ry_text) ry = rx;
            if (ry_text && !rx_text) rx = ry;
            rx = std::min(rx, w / 2.0);
            ry = std::min(ry, h / 2.0);
            if (rx == 0.0 || ry == 0.0) {
                Subpath sub;
                sub.closed = true;
                sub.has_segments = true;
                sub.points = {map(Vec2(x, y)), map(Vec2(x + w, y)), map(Vec2(x + w, y + h)),
                              map(Vec2(x, y + h))};
                return {sub};
            }
            const std::string arc = " A" + fmt(rx) + " " + fmt(ry) + " 0 0 1 ";
            return path("M" + fmt(x + rx) + " " + fmt(y) + " H" + fmt(x + w - rx) + arc +
                        fmt(x + w) + " " + fmt(y + ry) + " V" + fmt(y + h - ry) + arc +
                        fmt(x + w - rx) + " " + fmt(y + h) + " H" + fmt(x + rx) + arc + fmt(x) +
                        " " + fmt(y + h - ry) + " V" + fmt(y + ry) + arc + fmt(x + rx) + " " +
                        fmt(y) + " Z");
        }
        if (name == "circle" || name == "ellipse") {
            const double cx = num("cx"), cy = num("cy");
            double rx = 0.0, ry = 0.0;
            if (name == "circle") {
                rx = ry = non_negative("r", num("r"));
            } else {
                rx = non_negative("rx", num("rx"));
                ry = non_negative("ry", num("ry"));
            }
            if (rx == 0.0 || ry == 0.0) return {};
            const std::string arc = " A" + fmt(rx) + " " + fmt(ry) + " 0 0 1 ";
            return path("M" + fmt(cx + rx) + " " + fmt(cy) + arc + fmt(cx - rx) + " " + fmt(cy) +
                        arc + fmt(cx + rx) + " " + fmt(cy) + " Z");
        }
        return {};
    }

    void read_shape(const tinyxml2::XMLElement* e, std::string_view name, const Affine& m,
                    const Origin& origin) {
        const std::vector<Subpath> subpaths = shape_subpaths(e, name, OutputMap(m), origin);
        if (subpaths.empty()) return;

        Layer base;
        auto check = [&](const char* attribute, bool ok, const char* range) {
            if (!ok)
                fail(origin, std::string(attribute) + "='" +
                                 std::string(trim(e->Attribute(attribute))) + "' must be " + range);
        };
        base.thickness = number_attribute(e, "data-thickness", 0.0, origin);
        check("data-thickness", base.thickness >= 0.0, ">= 0");
        base.weight = number_attribute(e, "data-weight", 1.0, origin);
        check("data-weight", base.weight > 0.0, "> 0");
        for (const char* attribute : {"data-alpha", "data-beta"}) {
            if (!e->Attribute(attribute)) continue;
            const double value = number_attribute(e, attribute, 0.0, origin);
            check(attribute, value >= 0.0 && value <= 1.0, "in [0, 1]");
            (std::strcmp(attribute, "data-alpha") == 0 ? base.alpha : base.beta) = value;
        }
        if (const char* outer = e->Attribute("data-outer")) {
            any_outer_ = true;
            std::vector<std::string> names;
            std::string_view rest(outer);
            while (!rest.empty()) {
                const std::size_t cut = rest.find_first_of(", \t\n\r\f");
                const std::string_view token = rest.substr(0, cut);
                if (!token.empty()) {
                    names.push_back(name_of(token));
                    // An escaped separator: a name that data-outer cannot list (nor write back).
                    if (names.back().find_first_of(", \t\n\r\f") != std::string::npos)
                        fail(origin, "data-outer names '" + excerpt(names.back()) +
                                         "', which holds a space or comma");
                }
                rest = cut == std::string_view::npos ? std::string_view() : rest.substr(cut + 1);
            }
            base.outer = std::move(names);
        }

        const char* id = e->Attribute("id");
        for (std::size_t k = 0; k < subpaths.size(); ++k) {
            Layer layer = base;
            if (id && *id)
                layer.name = k == 0 ? name_of(id) : name_of(id) + "_" + std::to_string(k + 1);
            else
                layer.name = "layer_" + std::to_string(layers_.size());
            layer.points = subpaths[k].points;
            layer.closed = subpaths[k].closed;
            Layer copy = layer;  // checked here for the element's line; the scene keeps its own
            try {
                validate_layer(copy);
            } catch (const InvalidInput& error) {
                fail(origin, error.what());
            }
            layers_.push_back(std::move(layer));
            origins_.push_back(origin);
        }
    }

    const std::string& source_;
    const SvgReadParams& params_;
    bool escaped_names_ = false;
    std::size_t curve_points_ = 0;  // vertices made by flattening so far
    std::vector<Layer> layers_;
    std::vector<Origin> origins_;
    bool any_outer_ = false;
};

// ---------------------------------------------------------------------------------------------
// Writing

constexpr std::array<const char*, 10> kPalette = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728",
                                                  "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
                                                  "#bcbd22", "#17becf"};

std::string xml_escape(std::string_view text) {
    std::string out;
    out.reserve(text.size());
    for (const char c : text) {
        switch (c) {
            case '&':
                out += "&amp;";
                break;
            case '<':
                out += "&lt;";
                break;
            case '>':
                out += "&gt;";
                break;
            case '"':
                out += "&quot;";
                break;
            case '\'':
                out += "&apos;";
                break;
            case '\n':
                out += "&#10;";
                break;
            case '\r':
                out += "&#13;";
                break;
            case '\t':
                out += "&#9;";
                break;
            default:
                out += c;
        }
    }
    return out;
}

std::string attribute(std::string_view name, std::string_view value) {
    return " " + std::string(name) + "=\"" + xml_escape(value) + "\"";
}

std::string points_text(const Layer& layer) {
    std::string out;
    for (std::size_t i = 0; i < layer.points.size(); ++i) {
        if (i > 0) out += ' ';
        out += format_number(layer.points[i].x) + "," + format_number(-layer.points[i].y);
    }
    return out;
}

// `name`: the layer's name as the document writes it.
std::string layer_summary(const Layer& layer, const std::string& name) {
    std::string out = name + ": " + (layer.closed ? "closed" : "open") + ", " +
                      std::to_string(layer.points.size()) + " points, thickness " +
                      format_number(layer.thickness) + ", weight " + format_number(layer.weight);
    if (layer.alpha) out += ", alpha " + format_number(*layer.alpha);
    if (layer.beta) out += ", beta " + format_number(*layer.beta);
    return out;
}

}  // namespace

void validate(const SvgReadParams& params) {
    if (!std::isfinite(params.flatten_tolerance) || params.flatten_tolerance <= 0.0)
        throw InvalidInput("parse_scene_svg: params.flatten_tolerance must be > 0 (got " +
                           format_number(params.flatten_tolerance) + ")");
    if (params.max_curve_points < 1)
        throw InvalidInput("parse_scene_svg: params.max_curve_points must be >= 1 (got 0)");
}

void validate(const SvgWriteParams& params) {
    if (!std::isfinite(params.width_px) || params.width_px <= 0.0)
        throw InvalidInput("scene_to_svg: params.width_px must be > 0 (got " +
                           format_number(params.width_px) + ")");
    if (!std::isfinite(params.stroke_px) || params.stroke_px < 0.0)
        throw InvalidInput("scene_to_svg: params.stroke_px must be >= 0 (got " +
                           format_number(params.stroke_px) + ")");
}

Scene parse_scene_svg(std::string_view text, const std::string& source,
                      const SvgReadParams& params) {
    validate(params);
    tinyxml2::XMLDocument doc;
    if (doc.Parse(text.data(), text.size()) != tinyxml2::XML_SUCCESS)
        throw InvalidInput(source + ":" + std::to_string(doc.ErrorLineNum()) +
                           ": malformed XML: " + doc.ErrorStr());
    const tinyxml2::XMLElement* root = doc.RootElement();
    if (!root) throw InvalidInput(source + ": no root element");
    if (local_name(root->Name()) != "svg")
        throw InvalidInput(source + ":" + std::to_string(root->GetLineNum()) +
                           ": root element is <" + root->Name() + ">, not <svg>");
    const char* names = root->Attribute(kNamesAttribute);
    SvgReader reader(source, params, names && std::string_view(names) == kEscapedNames);
    Affine m;
    if (const char* t = root->Attribute("transform"))
        m = parse_transform(t, Origin{source, root->GetLineNum(), "<svg>"});
    reader.walk(root, m);
    const char* units = root->Attribute("data-strata-units");
    return reader.finish(units ? reader.name_of(units) : "");
}

Scene read_scene_svg(const std::filesystem::path& path, const SvgReadParams& params) {
    return parse_scene_svg(read_text_file(path), path.string(), params);
}

std::string scene_to_svg(const Scene& scene, const SvgWriteParams& params) {
    validate(params);
    const bool explicit_outer = !scene.is_implicit_stack();
    // Only names that data-outer lists must be free of separators (an unlinked layer named
    // " a" is written as it is: fuzz_svg read such an id and could not write it back).
    if (explicit_outer)
        for (std::size_t i = 0; i < scene.size(); ++i)
            for (const std::size_t j : scene.outer_of(i))
                if (scene.layer(j).name.find_first_of(", \t\n\r\f") != std::string::npos)
                    throw InvalidInput("scene_to_svg: layer '" + excerpt(scene.layer(j).name) +
                                       "': a name with a space or comma cannot be written in "
                                       "data-outer");

    // Names XML cannot hold: every name of the document as shown_text() shows it.
    bool escaped = !is_xml_text(scene.units());
    for (const Scene* s : {&scene, params.underlay})
        if (s)
            for (const Layer& layer : s->layers()) escaped = escaped || !is_xml_text(layer.name);
    const auto written = [escaped](std::string_view name) {
        return escaped ? shown_text(name, std::numeric_limits<std::size_t>::max())
                       : std::string(name);
    };

    Box2 box = scene.bounds();
    if (params.underlay) box.extend(params.underlay->bounds());
    if (box.is_empty()) box = Box2{Vec2(0.0), Vec2(1.0)};
    const Vec2 size = box.size();
    double extent = std::max(size.x, size.y);
    if (!(extent > 0.0)) extent = std::max(1.0, std::max(std::abs(box.min.x), std::abs(box.min.y)));
    const double margin = 0.05 * extent;
    const double view_x = box.min.x - margin, view_y = -box.max.y - margin;
    const double view_w = size.x + 2.0 * margin, view_h = size.y + 2.0 * margin;
    const double height_px = params.width_px * view_h / view_w;
    const double px = view_w / params.width_px;  // user units per pixel
    // In user units, so that viewers without vector-effect support draw the same width.
    const std::string stroke = format_number(params.stroke_px * px);

    std::string out = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg";
    out += attribute("xmlns", "http://www.w3.org/2000/svg");
    out += attribute("version", "1.1");
    out += attribute("width", format_number(params.width_px));
    out += attribute("height", format_number(height_px));
    out += attribute("viewBox", format_number(view_x) + " " + format_number(view_y) + " " +
                                    format_number(view_w) + " " + format_number(view_h));
    if (escaped) out += attribute(kNamesAttribute, kEscapedNames);
    if (!scene.units().empty()) out += attribute("data-strata-units", written(scene.units()));
    out += ">\n";

    auto element_name = [](const Layer& layer) { return layer.closed ? "polygon" : "polyline"; };
    auto dots = [&](const Layer& layer, const char* colour) {
        std::string g = "<g" + attribute("data-strata-role", "vertices") +
                        attribute("fill", colour) + attribute("stroke", "none") + ">\n";
        const std::string r = format_number(std::max(1.0, 1.5 * params.stroke_px) * px);
        for (const Vec2& p : layer.points)
            g += "  <circle" + attribute("cx", format_number(p.x)) +
                 attribute("cy", format_number(-p.y)) + attribute("r", r) + "/>\n";
        return g + "</g>\n";
    };

    if (params.underlay) {
        out += "<g" + attribute("id", "underlay") + attribute("data-strata-role", "underlay") +
               attribute("opacity", "0.35") + attribute("fill", "none") +
               attribute("stroke", "#999999") + ">\n";
        for (const Layer& layer : params.underlay->layers()) {
            out += "  <" + std::string(element_name(layer)) +
                   attribute("points", points_text(layer)) + attribute("stroke-width", stroke) +
                   "><title>" +
                   xml_escape("underlay " + layer_summary(layer, written(layer.name))) +
                   "</title></" + element_name(layer) + ">\n";
        }
        out += "</g>\n";
    }

    for (std::size_t i = 0; i < scene.size(); ++i) {
        const Layer& layer = scene.layer(i);
        const char* colour = kPalette[i % kPalette.size()];
        out += "<" + std::string(element_name(layer)) + attribute("id", written(layer.name)) +
               attribute("points", points_text(layer)) + attribute("fill", "none") +
               attribute("stroke", colour) + attribute("stroke-width", stroke) +
               attribute("stroke-linejoin", "round") +
               attribute("data-thickness", format_number(layer.thickness)) +
               attribute("data-weight", format_number(layer.weight));
        if (layer.alpha) out += attribute("data-alpha", format_number(*layer.alpha));
        if (layer.beta) out += attribute("data-beta", format_number(*layer.beta));
        if (explicit_outer) {
            std::string names;
            for (const std::size_t j : scene.outer_of(i))
                names += (names.empty() ? "" : " ") + written(scene.layer(j).name);
            out += attribute("data-outer", names);
        }
        out += "><title>" + xml_escape(layer_summary(layer, written(layer.name))) + "</title></" +
               element_name(layer) + ">\n";
        if (params.draw_vertices) out += dots(layer, colour);
    }
    if (!params.marks.empty()) {
        const std::string r = format_number(4.0 * std::max(1.0, params.stroke_px) * px);
        auto y = [](double v) { return format_number(0.0 - v); };  // 0 -> "0", not "-0"
        out += "<g" + attribute("data-strata-role", "marks") + attribute("fill", "none") +
               attribute("stroke", "#d00000") + attribute("stroke-width", stroke) + ">\n";
        for (const SvgMark& mark : params.marks) {
            // (A title XML cannot hold is shown as the escaped names are.)
            const std::string shown =
                is_xml_text(mark.title)
                    ? mark.title
                    : shown_text(mark.title, std::numeric_limits<std::size_t>::max());
            const std::string title = "<title>" + xml_escape(shown) + "</title>";
            out += "  <circle" + attribute("cx", format_number(mark.at.x)) +
                   attribute("cy", y(mark.at.y)) + attribute("r", r) + ">" + title + "</circle>\n";
            if (mark.to != mark.at)
                out += "  <line" + attribute("x1", format_number(mark.at.x)) +
                       attribute("y1", y(mark.at.y)) + attribute("x2", format_number(mark.to.x)) +
                       attribute("y2", y(mark.to.y)) + ">" + title + "</line>\n";
        }
        out += "</g>\n";
    }
    out += "</svg>\n";
    return out;
}

namespace {

// The height attribute (pixels) of the first <svg> element of `svg`.
double svg_height(const std::string& svg) {
    const std::size_t at = svg.find(" height=\"");
    return at == std::string::npos ? 0.0 : std::strtod(svg.c_str() + at + 9, nullptr);
}

}  // namespace

std::string panels_to_svg(const std::vector<SvgPanel>& panels, const SvgWriteParams& params) {
    validate(params);
    if (panels.empty()) throw InvalidInput("panels_to_svg: no panel");
    Box2 box;
    for (std::size_t i = 0; i < panels.size(); ++i) {
        if (!panels[i].scene)
            throw InvalidInput("panels_to_svg: panels[" + std::to_string(i) + "] has no scene");
        box.extend(panels[i].scene->bounds());
    }
    const bool stacked = box.size().x > box.size().y;
    const double caption = 24.0, gap = 8.0;
    double total_w = 0.0, total_h = 0.0;
    std::string body;
    for (const SvgPanel& panel : panels) {
        SvgWriteParams one = params;
        one.underlay = panel.underlay;
        one.marks = panel.marks;
        std::string svg = scene_to_svg(*panel.scene, one);
        svg = svg.substr(svg.find("<svg"));  // drop the XML declaration
        const double h = svg_height(svg);
        const double x = stacked ? 0.0 : total_w, y = stacked ? total_h : 0.0;
        body += "<text" + attribute("x", format_number(x + 4.0)) +
                attribute("y", format_number(y + caption - 6.0)) +
                attribute("font-family", "sans-serif") + attribute("font-size", "16") + ">" +
                xml_escape(panel.title) + "</text>\n";
        body += "<g" +
                attribute("transform", "translate(" + format_number(x) + " " +
                                           format_number(y + caption) + ")") +
                ">\n" + svg + "</g>\n";
        if (stacked) {
            total_w = std::max(total_w, params.width_px);
            total_h += caption + h + gap;
        } else {
            total_w += params.width_px + gap;
            total_h = std::max(total_h, caption + h);
        }
    }
    std::string out = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg";
    out += attribute("xmlns", "http://www.w3.org/2000/svg");
    out += attribute("version", "1.1");
    out += attribute("width", format_number(total_w));
    out += attribute("height", format_number(total_h));
    out += ">\n<rect" + attribute("width", "100%") + attribute("height", "100%") +
           attribute("fill", "white") + "/>\n" + body + "</svg>\n";
    return out;
}

void write_scene_svg(const Scene& scene, const std::filesystem::path& path,
                     const SvgWriteParams& params) {
    write_file_atomic(path, scene_to_svg(scene, params));
}

}  // namespace strata
