#include "strata/io/json_io.h"

#include "strata/core/error.h"
#include "strata/core/format.h"
#include "strata/io/atomic_file.h"

#include <simdjson.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
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

// The common scene read by simdjson's DOM parser (which picks the CPU's SIMD kernels at run
// time), before the readers below: every key one strata knows, numbers and strings as
// nlohmann reads them (an integer token as a 64-bit integer, so "-0" is +0; strings
// unescaped). Anything else (an unknown key, whose value must be kept as written; a duplicate
// key; a syntax or type error; a number out of range) makes read() return false, and the
// readers below take the text and name what is wrong.
class FastScene {
  public:
    // `text` followed by `capacity` - text.size() readable bytes: simdjson reads up to
    // SIMDJSON_PADDING bytes past the end, and copies a text without that room.
    bool read(std::string_view text, std::size_t capacity) {
        if (text.empty()) return false;  // (an empty view may hold no buffer at all)
        simdjson::dom::parser parser;
        simdjson::dom::element root;
        const bool parsed =
            capacity >= text.size() + simdjson::SIMDJSON_PADDING
                ? !parser.parse(simdjson::padded_string_view(text.data(), text.size(), capacity))
                       .get(root)
                : !parser.parse(text.data(), text.size()).get(root);
        if (!parsed) return false;
        bool has_layers = false;
        const bool read = fields(root, [&](std::string_view key, simdjson::dom::element v) {
            if (key == "strata") {
                const auto type = v.type();
                return (type == simdjson::dom::element_type::INT64 ||
                        type == simdjson::dom::element_type::UINT64) &&
                       number(v) == 1.0;
            }
            if (key == "units") return string(v, units);
            if (key == "layers") {
                has_layers = true;
                return items(v, [&](simdjson::dom::element item) { return layer(item); });
            }
            return false;
        });
        return read && has_layers && !layers.empty();
    }

    std::string units;
    std::vector<Layer> layers;

  private:
    // The number `v` as a double (NaN when it is not a number, which no JSON number reads as).
    static double number(simdjson::dom::element v) {
        switch (v.type()) {
            case simdjson::dom::element_type::INT64:
                return static_cast<double>(v.get_int64().value_unsafe());
            case simdjson::dom::element_type::UINT64:
                return static_cast<double>(v.get_uint64().value_unsafe());
            case simdjson::dom::element_type::DOUBLE:
                return v.get_double().value_unsafe();
            default:
                return std::numeric_limits<double>::quiet_NaN();
        }
    }
    static bool number(simdjson::dom::element v, double& out) {
        out = number(v);
        return !std::isnan(out);
    }
    static bool string(simdjson::dom::element v, std::string& out) {
        std::string_view s;
        if (v.get_string().get(s)) return false;
        out.assign(s);
        return true;
    }
    // Calls item(element) for each element of the array `v`; false when `v` is not an array or
    // an item() fails.
    template <class Item>
    static bool items(simdjson::dom::element v, Item&& item) {
        simdjson::dom::array array;
        if (v.get_array().get(array)) return false;
        for (simdjson::dom::element element : array)
            if (!item(element)) return false;
        return true;
    }
    // Calls value(key, element) for each field of the object `v`; false when `v` is not an
    // object, on a duplicate key, or when a value() fails.
    template <class Value>
    static bool fields(simdjson::dom::element v, Value&& value) {
        simdjson::dom::object object;
        if (v.get_object().get(object)) return false;
        std::vector<std::string_view> seen;
        for (const simdjson::dom::key_value_pair field : object) {
            if (std::find(seen.begin(), seen.end(), field.key) != seen.end()) return false;
            seen.push_back(field.key);
            if (!value(field.key, field.value)) return false;
        }
        return true;
    }
    bool layer(simdjson::dom::element v) {
        Layer& l = layers.emplace_back();
        l.name = "layer_" + std::to_string(layers.size() - 1);
        bool has_points = false;
        const bool read = fields(v, [&](std::string_view key, simdjson::dom::element x) {
            if (key == "name") return string(x, l.name);
            if (key == "closed") return !x.get_bool().get(l.closed);
            if (key == "thickness") return number(x, l.thickness);
            if (key == "weight") return number(x, l.weight);
            if (key == "alpha" || key == "beta") {
                if (x.is_null()) return true;
                double a = 0.0;
                if (!number(x, a)) return false;
                (key == "alpha" ? l.alpha : l.beta) = a;
                return true;
            }
            if (key == "outer") {
                l.outer.emplace();
                return items(x, [&](simdjson::dom::element name) {
                    return string(name, l.outer->emplace_back());
                });
            }
            if (key == "points") {
                has_points = true;
                simdjson::dom::array points;
                if (x.get_array().get(points)) return false;
                l.points.reserve(points.size());
                return items(x, [&](simdjson::dom::element point) {
                    simdjson::dom::array xy;
                    double px = 0.0, py = 0.0;
                    if (point.get_array().get(xy) || xy.size() != 2 ||
                        !number(xy.at(0).value_unsafe(), px) ||
                        !number(xy.at(1).value_unsafe(), py))
                        return false;
                    l.points.emplace_back(px, py);
                    return true;
                });
            }
            return false;
        });
        return read && has_points;
    }
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
            label = where + " ('" + shown_text(layer.name) + "')";
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

    // `capacity`: FastScene::read().
    Scene scene(std::string_view text, std::size_t capacity = 0) const {
        // FastScene takes 4 levels of nesting at most: no depth scan before it.
        if (FastScene fast; fast.read(text, capacity))
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
        // Keys and names from the file: shown with their control bytes escaped.
        for (const auto& [key, value] : metadata) kept.push_back("\"" + shown_text(key) + "\"");
        for (const Layer& l : parsed)
            for (const auto& [key, value] : l.extra)
                kept.push_back("'" + shown_text(l.name) + "'.\"" + shown_text(key) + "\"");

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

// `s` as a JSON string. JSON holds UTF-8 text only: a name read from an SVG id may hold other
// bytes, refused here by name rather than passed on as nlohmann's type_error.
std::string quoted(const std::string& s) {
    try {
        return json(s).dump();
    } catch (const json::type_error&) {
        throw InvalidInput("scene_to_json: '" + shown_text(s) +
                           "' is not UTF-8 text, which JSON cannot hold (rename it)");
    }
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
    const std::string text = read_text_file(path);  // with room to spare: read_text_file()
    return Reader(path.string()).scene(text, text.capacity());
}

void write_scene_json(const Scene& scene, const std::filesystem::path& path) {
    write_file_atomic(path, scene_to_json(scene));
}

}  // namespace strata
