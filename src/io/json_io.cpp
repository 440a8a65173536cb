#include "strata/io/json_io.h"

#include "strata/core/error.h"
#include "strata/core/format.h"
#include "strata/io/atomic_file.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <charconv>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace strata {

namespace {

using json = nlohmann::json;

// Line and column (1-based) of byte offset `offset` in `text`.
std::pair<std::size_t, std::size_t> line_column(std::string_view text, std::size_t offset) {
    offset = std::min(offset, text.size());
    std::size_t line = 1, column = 1;
    for (std::size_t i = 0; i < offset; ++i) {
        if (text[i] == '\n') {
            ++line;
            column = 1;
        } else {
            ++column;
        }
    }
    return {line, column};
}

// Deepest nesting of arrays/objects accepted. A scene needs 4 levels (top, layers, a layer's
// points, a point); metadata may nest further. nlohmann's DOM (its destructor and dump()) recurse
// per level, so an unbounded depth can overflow the stack.
constexpr std::size_t kMaxJsonDepth = 256;

// Byte offset of the first '[' or '{' that opens a level deeper than kMaxJsonDepth, skipping
// string contents; npos when the nesting stays within the limit.
std::size_t too_deep_at(std::string_view text) {
    std::size_t depth = 0;
    bool in_string = false;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (in_string) {
            if (c == '\\')
                ++i;
            else if (c == '"')
                in_string = false;
        } else if (c == '"') {
            in_string = true;
        } else if (c == '[' || c == '{') {
            if (++depth > kMaxJsonDepth) return i;
        } else if ((c == ']' || c == '}') && depth > 0) {
            --depth;
        }
    }
    return std::string_view::npos;
}

std::string shown(const json& value) {
    std::string text = value.dump();
    if (text.size() > 60) text = text.substr(0, 57) + "...";
    return text;
}

// The common case read without a document tree: nlohmann's SAX interface fills the layers
// directly, so a large scene costs its points and nothing more (the tree took about 10 times
// the memory of the points, and an allocation failure while the tree was being torn down
// aborted the process). Anything this reader does not accept as it stands (a syntax error, a
// wrong type, a duplicate key, a missing key) makes it give up, and the document-tree reader
// below reads the text again to name the problem exactly. Unknown keys are captured into a
// small tree each and kept as their JSON text, as the tree reader keeps them.
class SceneSax {
  public:
    using number_integer_t = json::number_integer_t;
    using number_unsigned_t = json::number_unsigned_t;
    using number_float_t = json::number_float_t;
    using string_t = json::string_t;
    using binary_t = json::binary_t;

    /// What was read; valid after a successful json::sax_parse().
    bool has_layers = false;
    std::string units;
    std::map<std::string, std::string> metadata;
    std::vector<Layer> layers;

    bool null() { return value(json(nullptr)); }
    bool boolean(bool v) { return value(json(v)); }
    bool number_integer(number_integer_t v) { return value(json(v)); }
    bool number_unsigned(number_unsigned_t v) { return value(json(v)); }
    bool number_float(number_float_t v, const string_t&) { return value(json(v)); }
    bool string(string_t& v) { return value(json(std::move(v))); }
    bool binary(binary_t&) { return false; }

    bool start_object(std::size_t) {
        if (capturing()) return open(json::object());
        if (at_.empty()) {
            at_.push_back(At::Root);
            return true;
        }
        if (at_.back() == At::Layers) {
            at_.push_back(At::Layer);
            layer_keys_.clear();
            layers.emplace_back();
            layers.back().name = "layer_" + std::to_string(layers.size() - 1);
            return true;
        }
        if (unknown_key()) return open(json::object());
        return false;
    }
    bool end_object() {
        if (capturing()) return close();
        if (at_.back() == At::Layer && layer_keys_.count("points") == 0) return false;
        at_.pop_back();
        return true;
    }
    bool key(string_t& k) {
        if (capturing()) {
            capture_key_ = k;
            return true;
        }
        std::set<std::string>& seen = at_.back() == At::Root ? root_keys_ : layer_keys_;
        if (!seen.insert(k).second) return false;  // a duplicate: the tree reader decides
        key_ = k;
        return true;
    }
    bool start_array(std::size_t) {
        if (capturing()) return open(json::array());
        switch (at_.empty() ? At::Root : at_.back()) {
            case At::Root:
                if (at_.empty()) return false;
                if (key_ == "layers") {
                    has_layers = true;
                    at_.push_back(At::Layers);
                    return true;
                }
                break;
            case At::Layer:
                if (key_ == "points" || key_ == "outer") {
                    at_.push_back(key_ == "points" ? At::Points : At::Outer);
                    if (key_ == "outer") layers.back().outer.emplace();
                    return true;
                }
                break;
            case At::Points:
                at_.push_back(At::Point);
                coordinates_ = 0;
                return true;
            default:
                return false;
        }
        return unknown_key() && open(json::array());
    }
    bool end_array() {
        if (capturing()) return close();
        if (at_.back() == At::Point) {
            if (coordinates_ != 2) return false;
            layers.back().points.emplace_back(xy_[0], xy_[1]);
        }
        at_.pop_back();
        return true;
    }
    /// A syntax error (or a number out of range): what nlohmann's own parser would throw.
    bool syntax_error = false;
    int error_id = 0;
    std::size_t error_byte = 0;
    std::string error_message;
    bool parse_error(std::size_t position, const std::string&,
                     const nlohmann::detail::exception& ex) {
        syntax_error = true;
        error_id = ex.id;
        error_byte = position;
        error_message = ex.what();
        return false;
    }

  private:
    enum class At { Root, Layers, Layer, Points, Point, Outer };

    bool capturing() const { return !capture_.empty(); }

    // The value of the current key is not one strata knows: it is captured.
    bool unknown_key() const {
        if (at_.back() == At::Root) return key_ != "strata" && key_ != "units" && key_ != "layers";
        if (at_.back() == At::Layer)
            return key_ != "name" && key_ != "closed" && key_ != "thickness" && key_ != "weight" &&
                   key_ != "alpha" && key_ != "beta" && key_ != "outer" && key_ != "points";
        return false;
    }

    // Captured values: a stack of the open containers, the outermost first.
    bool open(json container) {
        if (capturing()) capture_keys_.push_back(capture_key_);  // where it goes in its parent
        capture_.push_back(std::move(container));
        return true;
    }
    bool close() {
        json done = std::move(capture_.back());
        capture_.pop_back();
        if (capturing()) {
            const std::string k = std::move(capture_keys_.back());
            capture_keys_.pop_back();
            add(std::move(done), k);
            return true;
        }
        keep(done.dump());
        return true;
    }
    void add(json v, const std::string& k) {
        json& parent = capture_.back();
        if (parent.is_array())
            parent.push_back(std::move(v));
        else
            parent[k] = std::move(v);
    }
    void keep(std::string text) {
        if (at_.back() == At::Root)
            metadata.emplace(key_, std::move(text));
        else
            layers.back().extra.emplace(key_, std::move(text));
    }

    bool value(json v) {
        if (capturing()) {
            add(std::move(v), capture_key_);
            return true;
        }
        if (at_.empty()) return false;  // a top level that is not an object
        Layer* layer = layers.empty() ? nullptr : &layers.back();
        switch (at_.back()) {
            case At::Root:
                if (key_ == "strata") return v.is_number_integer() && v.get<long long>() == 1;
                if (key_ == "units") {
                    if (!v.is_string()) return false;
                    units = v.get<std::string>();
                    return true;
                }
                if (key_ == "layers") return false;
                keep(v.dump());
                return true;
            case At::Layer:
                if (key_ == "name") {
                    if (!v.is_string()) return false;
                    layer->name = v.get<std::string>();
                } else if (key_ == "closed") {
                    if (!v.is_boolean()) return false;
                    layer->closed = v.get<bool>();
                } else if (key_ == "thickness" || key_ == "weight") {
                    if (!v.is_number()) return false;
                    (key_ == "weight" ? layer->weight : layer->thickness) = v.get<double>();
                } else if (key_ == "alpha" || key_ == "beta") {
                    if (v.is_null()) return true;
                    if (!v.is_number()) return false;
                    (key_ == "alpha" ? layer->alpha : layer->beta) = v.get<double>();
                } else if (key_ == "outer" || key_ == "points") {
                    return false;
                } else {
                    keep(v.dump());
                }
                return true;
            case At::Point:
                if (!v.is_number() || coordinates_ == 2) return false;
                xy_[coordinates_++] = v.get<double>();
                return true;
            case At::Outer:
                if (!v.is_string()) return false;
                layer->outer->push_back(v.get<std::string>());
                return true;
            default:
                return false;  // a bare value in "layers" or "points"
        }
    }

    std::vector<At> at_;
    std::string key_;
    std::set<std::string> root_keys_, layer_keys_;
    double xy_[2] = {0.0, 0.0};
    int coordinates_ = 0;
    std::vector<json> capture_;
    std::vector<std::string> capture_keys_;
    std::string capture_key_;
};

// The common case read directly from the text, before either reader: a scene whose keys are
// all ones strata knows, strings without escapes or non-ASCII bytes, numbers by std::from_chars
// (correctly rounded, as nlohmann's strtod; an integer token goes through a 64-bit integer as
// nlohmann reads it, so "-0" stays +0). Anything else (unknown keys, a duplicate key, an
// escape, a syntax or type error, a number out of range) makes it give up and the readers
// above take the text: what it reads is what they read, at a fraction of the cost.
class FastScene {
  public:
    explicit FastScene(std::string_view text) : p_(text.data()), end_(text.data() + text.size()) {}

    bool read() {
        if (!object([&](std::string_view key) {
                if (key == "strata") {
                    double v = 0.0;
                    bool integer = false;
                    return number(v, &integer) && integer && v == 1.0;
                }
                if (key == "units") return string(units);
                if (key == "layers") {
                    has_layers = true;
                    return array([&] { return layer(); });
                }
                return false;
            }))
            return false;
        space();
        return p_ == end_ && has_layers && !layers.empty();
    }

    bool has_layers = false;
    std::string units;
    std::vector<Layer> layers;

  private:
    void space() {
        while (p_ != end_ && (*p_ == ' ' || *p_ == '\n' || *p_ == '\r' || *p_ == '\t')) ++p_;
    }
    bool take(char c) {
        space();
        if (p_ == end_ || *p_ != c) return false;
        ++p_;
        return true;
    }
    bool peek(char c) {
        space();
        return p_ != end_ && *p_ == c;
    }
    bool literal(std::string_view word) {
        space();
        if (static_cast<std::size_t>(end_ - p_) < word.size() ||
            std::string_view(p_, word.size()) != word)
            return false;
        p_ += word.size();
        return true;
    }
    // A string of printable ASCII without escapes.
    bool string(std::string& out) {
        if (!take('"')) return false;
        const char* first = p_;
        while (p_ != end_ && *p_ != '"') {
            const unsigned char c = static_cast<unsigned char>(*p_);
            if (c < 0x20 || c >= 0x80 || c == '\\') return false;
            ++p_;
        }
        if (p_ == end_) return false;
        out.assign(first, p_);
        ++p_;
        return true;
    }
    // A JSON number (its grammar checked here: from_chars accepts more).
    bool number(double& out, bool* integer = nullptr) {
        space();
        const char* first = p_;
        const char* q = p_;
        if (q != end_ && *q == '-') ++q;
        if (q == end_ || *q < '0' || *q > '9') return false;
        if (*q == '0')
            ++q;
        else
            while (q != end_ && *q >= '0' && *q <= '9') ++q;
        bool whole = true;
        if (q != end_ && *q == '.') {
            whole = false;
            ++q;
            if (q == end_ || *q < '0' || *q > '9') return false;
            while (q != end_ && *q >= '0' && *q <= '9') ++q;
        }
        if (q != end_ && (*q == 'e' || *q == 'E')) {
            whole = false;
            ++q;
            if (q != end_ && (*q == '+' || *q == '-')) ++q;
            if (q == end_ || *q < '0' || *q > '9') return false;
            while (q != end_ && *q >= '0' && *q <= '9') ++q;
        }
        p_ = q;
        if (integer) *integer = whole;
        if (whole) {
            if (*first == '-') {
                long long v = 0;
                const auto r = std::from_chars(first, q, v);
                if (r.ec == std::errc() && r.ptr == q) {
                    out = static_cast<double>(v);
                    return true;
                }
            } else {
                unsigned long long v = 0;
                const auto r = std::from_chars(first, q, v);
                if (r.ec == std::errc() && r.ptr == q) {
                    out = static_cast<double>(v);
                    return true;
                }
            }
            if (integer) *integer = false;  // nlohmann reads it as a float
        }
        const auto r = std::from_chars(first, q, out);
        return r.ec == std::errc() && r.ptr == q;
    }
    template <class Item>
    bool array(Item&& item) {
        if (!take('[')) return false;
        if (take(']')) return true;
        do {
            if (!item()) return false;
        } while (take(','));
        return take(']');
    }
    // An object without duplicate keys; value(key) reads the value of each.
    template <class Value>
    bool object(Value&& value) {
        if (!take('{')) return false;
        if (take('}')) return true;
        std::vector<std::string> seen;
        std::string key;
        do {
            if (!string(key) || !take(':')) return false;
            if (std::find(seen.begin(), seen.end(), key) != seen.end()) return false;
            seen.push_back(key);
            if (!value(std::string_view(key))) return false;
        } while (take(','));
        return take('}');
    }
    bool layer() {
        layers.emplace_back();
        Layer& l = layers.back();
        l.name = "layer_" + std::to_string(layers.size() - 1);
        bool has_points = false;
        const bool read = object([&](std::string_view key) {
            if (key == "name") return string(l.name);
            if (key == "closed") {
                if (literal("true")) {
                    l.closed = true;
                    return true;
                }
                l.closed = false;
                return literal("false");
            }
            if (key == "thickness") return number(l.thickness);
            if (key == "weight") return number(l.weight);
            if (key == "alpha" || key == "beta") {
                std::optional<double>& v = key == "alpha" ? l.alpha : l.beta;
                if (literal("null")) return true;
                double x = 0.0;
                if (!number(x)) return false;
                v = x;
                return true;
            }
            if (key == "outer") {
                l.outer.emplace();
                return array([&] {
                    std::string name;
                    if (!string(name)) return false;
                    l.outer->push_back(std::move(name));
                    return true;
                });
            }
            if (key == "points") {
                has_points = true;
                return array([&] {
                    double x = 0.0, y = 0.0;
                    if (!take('[') || !number(x) || !take(',') || !number(y) || !take(']'))
                        return false;
                    l.points.emplace_back(x, y);
                    return true;
                });
            }
            return false;
        });
        return read && has_points;
    }

    const char* p_;
    const char* end_;
};

class Reader {
  public:
    explicit Reader(std::string source) : source_(std::move(source)) {}

    [[noreturn]] void fail(const std::string& where, const std::string& what) const {
        throw InvalidInput(source_ + ": " + where + ": " + what);
    }

    double number(const json& value, const std::string& where) const {
        if (!value.is_number()) fail(where, "expected a number (got " + shown(value) + ")");
        return value.get<double>();
    }

    Layer layer(const json& object, std::size_t index) const {
        const std::string where = "layers[" + std::to_string(index) + "]";
        if (!object.is_object()) fail(where, "expected an object (got " + shown(object) + ")");
        Layer layer;
        layer.name = "layer_" + std::to_string(index);
        std::string label = where;
        if (auto it = object.find("name"); it != object.end()) {
            if (!it->is_string())
                fail(where + ".name", "expected a string (got " + shown(*it) + ")");
            layer.name = it->get<std::string>();
            label = where + " ('" + layer.name + "')";
        }
        bool has_points = false;
        for (auto it = object.begin(); it != object.end(); ++it) {
            const std::string& key = it.key();
            const json& value = it.value();
            const std::string at = label + "." + key;
            if (key == "name") {
                continue;
            } else if (key == "closed") {
                if (!value.is_boolean())
                    fail(at, "expected true or false (got " + shown(value) + ")");
                layer.closed = value.get<bool>();
            } else if (key == "thickness") {
                layer.thickness = number(value, at);
            } else if (key == "weight") {
                layer.weight = number(value, at);
            } else if (key == "alpha") {
                if (!value.is_null()) layer.alpha = number(value, at);
            } else if (key == "beta") {
                if (!value.is_null()) layer.beta = number(value, at);
            } else if (key == "outer") {
                if (!value.is_array())
                    fail(at, "expected an array of layer names (got " + shown(value) + ")");
                std::vector<std::string> names;
                for (std::size_t k = 0; k < value.size(); ++k) {
                    if (!value[k].is_string())
                        fail(at + "[" + std::to_string(k) + "]",
                             "expected a layer name (got " + shown(value[k]) + ")");
                    names.push_back(value[k].get<std::string>());
                }
                layer.outer = std::move(names);
            } else if (key == "points") {
                has_points = true;
                if (!value.is_array())
                    fail(at, "expected an array of [x, y] (got " + shown(value) + ")");
                layer.points.reserve(value.size());
                for (std::size_t k = 0; k < value.size(); ++k) {
                    const json& p = value[k];
                    if (!p.is_array() || p.size() != 2 || !p[0].is_number() || !p[1].is_number())
                        fail(at + "[" + std::to_string(k) + "]",
                             "expected [x, y] with two numbers (got " + shown(p) + ")");
                    layer.points.emplace_back(p[0].get<double>(), p[1].get<double>());
                }
            } else {
                layer.extra.emplace(key, value.dump());
            }
        }
        if (!has_points) fail(label, "missing \"points\"");
        return layer;
    }

    Scene scene(std::string_view text) const {
        // The direct reader nests 4 levels at most: no depth check before it.
        if (FastScene fast(text); fast.read())
            return finish(std::move(fast.layers), fast.units, {});
        if (const std::size_t deep = too_deep_at(text); deep != std::string_view::npos) {
            const auto [line, column] = line_column(text, deep);
            throw InvalidInput(source_ + ":" + std::to_string(line) + ":" + std::to_string(column) +
                               ": invalid JSON: nesting deeper than " +
                               std::to_string(kMaxJsonDepth) + " levels (found '" +
                               std::string(1, text[deep]) + "')");
        }
        SceneSax sax;
        const bool read = json::sax_parse(text.begin(), text.end(), &sax);
        if (read && sax.has_layers && !sax.layers.empty())
            return finish(std::move(sax.layers), sax.units, std::move(sax.metadata));
        if (sax.syntax_error) {
            // nlohmann's ids: 1xx syntax errors (with the byte), 4xx e.g. a number too large.
            if (sax.error_id >= 100 && sax.error_id < 200)
                syntax_failure(text, sax.error_message, sax.error_byte);
            value_failure(text, sax.error_message);
        }
        // A content error: the document tree names it (its path, key and value).
        json root;
        try {
            root = json::parse(text.begin(), text.end());
        } catch (const json::parse_error& e) {
            syntax_failure(text, e.what(), e.byte);
        } catch (const json::exception& e) {
            value_failure(text, e.what());
        }
        if (!root.is_object())
            fail("top level", "expected an object with \"layers\" (got " + shown(root) + ")");
        std::string units;
        std::map<std::string, std::string> metadata;
        const json* layers = nullptr;
        for (auto it = root.begin(); it != root.end(); ++it) {
            const std::string& key = it.key();
            if (key == "strata") {
                if (!it->is_number_integer() || it->get<long long>() != 1)
                    fail("strata",
                         "unsupported format version " + shown(*it) + " (this reader knows 1)");
            } else if (key == "units") {
                if (!it->is_string()) fail("units", "expected a string (got " + shown(*it) + ")");
                units = it->get<std::string>();
            } else if (key == "layers") {
                if (!it->is_array()) fail("layers", "expected an array (got " + shown(*it) + ")");
                layers = &*it;
            } else {
                metadata.emplace(key, it->dump());
            }
        }
        if (!layers) fail("top level", "missing \"layers\"");
        if (layers->empty()) fail("layers", "no layer");
        std::vector<Layer> parsed;
        for (std::size_t i = 0; i < layers->size(); ++i) parsed.push_back(layer((*layers)[i], i));
        return finish(std::move(parsed), units, std::move(metadata));
    }

  private:
    // A syntax error at byte `byte` (1-based, nlohmann's count) of `text`.
    [[noreturn]] void syntax_failure(std::string_view text, std::string message,
                                     std::size_t byte) const {
        const auto [line, column] = line_column(text, byte > 0 ? byte - 1 : 0);
        if (auto pos = message.find("syntax error"); pos != std::string::npos)
            message = message.substr(pos);
        throw InvalidInput(source_ + ":" + std::to_string(line) + ":" + std::to_string(column) +
                           ": invalid JSON: " + message);
    }

    // Another parse failure, e.g. a number too large for a double: nlohmann names the number
    // ("... parsing '1e999'") but not where it is, so it is looked for.
    [[noreturn]] void value_failure(std::string_view text, const std::string& message) const {
        std::string where;
        const std::size_t open = message.find("parsing '");
        const std::size_t close = open == std::string::npos ? open : message.rfind('\'');
        if (open != std::string::npos && close > open + 9) {
            const std::string token = message.substr(open + 9, close - open - 9);
            if (const std::size_t at = text.find(token); at != std::string_view::npos) {
                const auto [line, column] = line_column(text, at);
                where = ":" + std::to_string(line) + ":" + std::to_string(column);
            }
        }
        throw InvalidInput(source_ + where + ": invalid JSON: " + message);
    }

    // The scene from what either reader read: checks of the scene itself, and a note listing
    // the unknown keys kept.
    Scene finish(std::vector<Layer> parsed, const std::string& units,
                 std::map<std::string, std::string> metadata) const {
        std::vector<std::string> kept;
        for (const auto& [key, value] : metadata) kept.push_back("\"" + key + "\"");
        for (const Layer& l : parsed)
            for (const auto& [key, value] : l.extra)
                kept.push_back("'" + l.name + "'.\"" + key + "\"");

        Scene scene;
        try {
            scene = Scene(std::move(parsed), units);
        } catch (const InvalidInput& e) {
            throw InvalidInput(source_ + ": " + e.what());
        }
        scene.metadata = std::move(metadata);
        if (!kept.empty()) {
            std::string note = "kept " + std::to_string(kept.size()) + " unknown key(s) unchanged:";
            for (std::size_t k = 0; k < kept.size() && k < 8; ++k) note += " " + kept[k];
            if (kept.size() > 8) note += " ...";
            scene.add_note(note);
        }
        return scene;
    }

    std::string source_;
};

std::string quoted(const std::string& s) {
    return json(s).dump();
}

}  // namespace

Scene parse_scene_json(std::string_view text, const std::string& source) {
    return Reader(source).scene(text);
}

std::string scene_to_json(const Scene& scene) {
    std::string out = "{\n  \"strata\": 1";
    if (!scene.units().empty()) out += ",\n  \"units\": " + quoted(scene.units());
    for (const auto& [key, value] : scene.metadata) out += ",\n  " + quoted(key) + ": " + value;
    out += ",\n  \"layers\": [";
    for (std::size_t i = 0; i < scene.size(); ++i) {
        const Layer& layer = scene.layer(i);
        out += i == 0 ? "\n" : ",\n";
        out += "    {\"name\": " + quoted(layer.name) +
               ", \"closed\": " + (layer.closed ? "true" : "false") +
               ", \"thickness\": " + format_number(layer.thickness) +
               ", \"weight\": " + format_number(layer.weight);
        if (layer.alpha) out += ", \"alpha\": " + format_number(*layer.alpha);
        if (layer.beta) out += ", \"beta\": " + format_number(*layer.beta);
        if (layer.outer) {
            out += ", \"outer\": [";
            for (std::size_t k = 0; k < layer.outer->size(); ++k)
                out += (k ? ", " : "") + quoted((*layer.outer)[k]);
            out += "]";
        }
        for (const auto& [key, value] : layer.extra) out += ", " + quoted(key) + ": " + value;
        out += ",\n     \"points\": [";
        for (std::size_t k = 0; k < layer.points.size(); ++k) {
            const Vec2& p = layer.points[k];
            out += (k ? ", [" : "[") + format_number(p.x) + ", " + format_number(p.y) + "]";
        }
        out += "]}";
    }
    out += "\n  ]\n}\n";
    return out;
}

Scene read_scene_json(const std::filesystem::path& path) {
    return parse_scene_json(read_text_file(path), path.string());
}

void write_scene_json(const Scene& scene, const std::filesystem::path& path) {
    write_file_atomic(path, scene_to_json(scene));
}

}  // namespace strata
