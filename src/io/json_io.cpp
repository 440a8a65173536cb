#include "strata/io/json_io.h"

#include "strata/core/error.h"
#include "strata/core/format.h"
#include "strata/io/atomic_file.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <utility>

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
        if (const std::size_t deep = too_deep_at(text); deep != std::string_view::npos) {
            const auto [line, column] = line_column(text, deep);
            throw InvalidInput(source_ + ":" + std::to_string(line) + ":" + std::to_string(column) +
                               ": invalid JSON: nesting deeper than " +
                               std::to_string(kMaxJsonDepth) + " levels (found '" +
                               std::string(1, text[deep]) + "')");
        }
        json root;
        try {
            root = json::parse(text.begin(), text.end());
        } catch (const json::parse_error& e) {
            const std::size_t offset = e.byte > 0 ? e.byte - 1 : 0;
            const auto [line, column] = line_column(text, offset);
            std::string message = e.what();
            if (auto pos = message.find("syntax error"); pos != std::string::npos)
                message = message.substr(pos);
            throw InvalidInput(source_ + ":" + std::to_string(line) + ":" + std::to_string(column) +
                               ": invalid JSON: " + message);
        } catch (const json::exception& e) {  // e.g. a number too large for a double
            // nlohmann names the number ("... parsing '1e999'") but not where it is: find it.
            const std::string message = e.what();
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

  private:
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
