#include "strata/core/error.h"
#include "strata/io/atomic_file.h"
#include "strata/io/json_io.h"
#include "support/fixtures.h"
#include "support/require.h"

#include <catch2/catch.hpp>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

using namespace strata;
using Catch::Matchers::Contains;

namespace {

const char* kExample = R"({
  "strata": 1, "units": "m", "producer": {"tool": "x", "version": 3},
  "layers": [
    {"name": "body", "closed": true, "thickness": 0.01, "weight": 4, "outer": ["shirt"],
     "points": [[0, 0], [1, 0], [1, 1], [0, 1]]},
    {"name": "shirt", "closed": true, "thickness": 0.02, "alpha": 0.5, "beta": 0.25,
     "colour": "red", "outer": [],
     "points": [[-0.5, -0.5], [1.5, -0.5], [1.5, 1.5], [-0.5, 1.5]]}
  ]
})";

}  // namespace

TEST_CASE("the documented example parses with every field", "[io][json]") {
    const Scene scene = parse_scene_json(kExample, "example.json");
    REQUIRE(scene.size() == 2);
    CHECK(scene.units() == "m");
    CHECK(scene.layer(0).weight == 4.0);
    CHECK(scene.layer(1).alpha == 0.5);
    CHECK(scene.layer(1).beta == 0.25);
    CHECK(scene.relation(0, 1) == Relation::Under);
    CHECK(scene.required_separation(0, 1) == Approx(0.015));
    // Unknown keys are kept and noted, never dropped.
    CHECK(scene.metadata.at("producer") == R"({"tool":"x","version":3})");
    CHECK(scene.layer(1).extra.at("colour") == "\"red\"");
    REQUIRE_FALSE(scene.diagnostics().notes.empty());
    CHECK_THAT(scene.diagnostics().notes.back(),
               Contains("\"producer\"") && Contains("\"colour\""));
}

TEST_CASE("unknown keys keep their nested values, and a duplicate key keeps the last value",
          "[io][json]") {
    // Read without a document tree; unknown values are captured into one each.
    const Scene scene = parse_scene_json(R"({"strata": 1,
        "meta": {"z": [1, {"b": [2.5, -3, true]}, "s"], "a": null, "e": {}, "f": []},
        "layers": [{"points": [[0, 0], [1, 0]], "x": [[1], [2, {"k": "v"}]], "n": 7}]})");
    CHECK(scene.metadata.at("meta") ==
          R"({"a":null,"e":{},"f":[],"z":[1,{"b":[2.5,-3,true]},"s"]})");
    CHECK(scene.layer(0).extra.at("x") == R"([[1],[2,{"k":"v"}]])");
    CHECK(scene.layer(0).extra.at("n") == "7");
    CHECK(scene.layer(0).name == "layer_0");
    // Duplicate keys: the document-tree reader decides (the last value wins), as before.
    const Scene twice = parse_scene_json(R"({"layers": [{"points": [[0, 0], [1, 0]]}],
        "layers": [{"name": "b", "points": [[0, 1], [2, 1], [3, 1]], "points": [[5, 5], [6, 6]]}]})");
    REQUIRE(twice.size() == 1);
    CHECK(twice.layer(0).name == "b");
    REQUIRE(twice.layer(0).points.size() == 2);
    CHECK(twice.layer(0).points[1] == Vec2(6.0, 6.0));
}

TEST_CASE("JSON round trips are exact", "[io][json]") {
    SECTION("generated scenes") {
        for (const Scene& scene : {test::nested_circles(3, 37, 1.0 / 3.0, 0.1, 0.01),
                                   test::stacked_sines(5, 101), test::spiral(3.5, 200)}) {
            test::require_same_scene(scene, parse_scene_json(scene_to_json(scene)), true);
        }
    }
    SECTION("a file with metadata, params and explicit nesting") {
        const Scene scene = parse_scene_json(kExample);
        test::require_same_scene(scene, parse_scene_json(scene_to_json(scene)), true);
    }
    SECTION("every real slice") {
        for (const char* name : {"cipc_multilayer_y+0.00.json", "cipc_multilayer_y-0.15.json",
                                 "cipc_multilayer_y-0.30.json", "mh_casualsuit03_y+1.50.json",
                                 "mh_casualsuit03_y+4.00.json", "mh_casualsuit05_y+4.00.json",
                                 "mh_elegantsuit01_y+0.50.json", "mh_elegantsuit01_y+1.50.json"}) {
            INFO(name);
            const Scene scene = read_scene_json(test::test_data(std::string("slices/") + name));
            CHECK_FALSE(scene.is_implicit_stack());
            CHECK(scene.metadata.count("source") == 1);
            test::require_same_scene(scene, parse_scene_json(scene_to_json(scene)), true);
        }
    }
}

TEST_CASE("names with controls round trip; a name that is not UTF-8 is refused by name",
          "[io][json]") {
    std::vector<Layer> layers(2);
    layers[0].name = "\033[1mbold\\";
    layers[0].points = {{0.0, 0.0}, {1.0, 0.0}};
    layers[1].name = "c1\302\2332";
    layers[1].points = {{0.0, 1.0}, {1.0, 1.0}};
    const Scene scene(layers, "c\001m");
    const std::string text = scene_to_json(scene);
    CHECK(text.find('\033') == std::string::npos);
    CHECK_THAT(text, Contains(R"("\u001b[1mbold\\")"));
    test::require_same_scene(scene, parse_scene_json(text), true);
    // A lone 0x9b (an SVG id can hold one): JSON holds UTF-8 only.
    layers[1].name = "a\233z";
    CHECK_THROWS_AS(scene_to_json(Scene(layers)), InvalidInput);
    CHECK_THROWS_WITH(scene_to_json(Scene(layers)), Contains("'a\\x9bz' is not UTF-8"));
    layers[1].name = "b";
    CHECK_THROWS_WITH(scene_to_json(Scene(layers, "c\377")), Contains("'c\\xff' is not UTF-8"));
}

TEST_CASE("bad JSON names the file, line and column", "[io][json]") {
    CHECK_THROWS_WITH(
        parse_scene_json("{\n  \"layers\": [\n    {\"points\": [[0, 0], [1 1]]}\n  ]\n}",
                         "bad.json"),
        Contains("bad.json:3:") && Contains("invalid JSON"));
    CHECK_THROWS_WITH(parse_scene_json("{\"layers\": [", "cut.json"), Contains("cut.json:1:13"));
}

TEST_CASE("deep nesting is refused with its position, not a stack overflow", "[io][json]") {
    const std::string deep = std::string(100000, '[') + std::string(100000, ']');
    CHECK_THROWS_WITH(parse_scene_json(deep, "deep.json"),
                      Contains("deep.json:1:257") && Contains("nesting deeper than 256"));
    // Brackets inside strings do not count: this scene passes the depth scan and is refused
    // only for having no layer.
    const std::string text = R"({"layers": [], "note": ")" + std::string(1000, '[') + "\"}";
    CHECK_THROWS_WITH(parse_scene_json(text, "s.json"),
                      Contains("no layer") && !Contains("nesting"));
    // A number too large for a double: its line:column (where the number starts) and text.
    CHECK_THROWS_WITH(parse_scene_json(R"({"layers": [[1e999]]})", "big.json"),
                      Contains("big.json:1:14") && Contains("1e999"));
}

TEST_CASE("bad content names the layer, the key and the value", "[io][json]") {
    auto fails = [](const std::string& text) {
        try {
            parse_scene_json(text, "f.json");
        } catch (const InvalidInput& e) {
            return std::string(e.what());
        }
        FAIL("no exception for " << text);
        return std::string();
    };
    CHECK_THAT(fails(R"({"layers": [{"name": "a", "points": [[0, 0], [1, "x"]]}]})"),
               Contains("f.json") && Contains("('a').points[1]") && Contains("[1,\"x\"]"));
    CHECK_THAT(
        fails(R"({"layers": [{"name": "a", "thickness": "thick", "points": [[0, 0], [1, 0]]}]})"),
        Contains("('a').thickness") && Contains("\"thick\""));
    CHECK_THAT(
        fails(R"({"layers": [{"name": "a", "thickness": -2, "points": [[0, 0], [1, 0]]}]})"),
        Contains("f.json") && Contains("layer 'a'") && Contains("thickness") && Contains("got -2"));
    CHECK_THAT(fails(R"({"layers": [{"name": "a", "closed": 1, "points": [[0, 0], [1, 0]]}]})"),
               Contains("('a').closed") && Contains("true or false"));
    CHECK_THAT(fails(R"({"layers": [{"name": "a"}]})"),
               Contains("('a')") && Contains("missing \"points\""));
    CHECK_THAT(fails(R"({"layers": [{"name": "a", "outer": ["b"], "points": [[0, 0], [1, 0]]}]})"),
               Contains("'b'") && Contains("not a layer"));
    CHECK_THAT(fails(R"({"strata": 2, "layers": []})"), Contains("unsupported format version 2"));
    CHECK_THAT(fails(R"({"layer": []})"), Contains("missing \"layers\""));
    CHECK_THAT(fails(R"([1, 2])"), Contains("expected an object"));
    CHECK_THAT(fails(R"({"layers": [{"name": "a", "points": [[0, 0], [1e999, 0]]}]})"),
               Contains("f.json") && Contains("overflow") && Contains("1e999"));
}

TEST_CASE("writing is atomic and never overwrites an input", "[io][json]") {
    namespace fs = std::filesystem;
    const fs::path dir = fs::temp_directory_path() / "strata_test_json_io";
    fs::remove_all(dir);
    fs::create_directories(dir);
    const fs::path file = dir / "scene.json";
    const Scene scene = test::nested_circles(2, 8);
    write_scene_json(scene, file);
    test::require_same_scene(scene, read_scene_json(file), true);
    CHECK_THROWS_AS(ensure_not_an_input(file, {dir / "other.json", file}), InvalidInput);
    CHECK_NOTHROW(ensure_not_an_input(dir / "new.json", {file}));
    // A write into a missing folder fails cleanly and leaves nothing behind.
    CHECK_THROWS_WITH(write_scene_json(scene, dir / "missing" / "x.json"),
                      Contains("does not exist"));
    CHECK(std::distance(fs::directory_iterator(dir), fs::directory_iterator()) == 1);
    CHECK_THROWS_WITH(read_scene_json(dir / "absent.json"),
                      Contains("absent.json") && Contains("cannot open"));
    fs::remove_all(dir);
}

TEST_CASE("the direct reader reads numbers and fields as the SAX reader does", "[io][json]") {
    // An unknown root key sends a text to the SAX reader; without it, the direct reader reads
    // it. Both must give the same bits (signs of zeros, integers beyond 2^53, long mantissas).
    const std::vector<std::string> numbers = {"0",
                                              "-0",
                                              "-0.0",
                                              "1",
                                              "-1",
                                              "0.1",
                                              "1e5",
                                              "1E-3",
                                              "-2.5e+2",
                                              "12345678901234567890",
                                              "123456789012345678901234",
                                              "-9223372036854775809",
                                              "9007199254740993",
                                              "1e308",
                                              "2.2250738585072014e-308",
                                              "0.30000000000000004",
                                              "3.141592653589793238462643383279"};
    auto text = [](const std::string& x, const std::string& y, bool unknown) {
        return std::string("{\"strata\": 1, \"units\": \"mm\",") + (unknown ? "\"x\": 1," : "") +
               "\"layers\": [{\"name\": \"a\", \"closed\": false, \"thickness\": 1e-3" +
               ", \"weight\": 2, \"alpha\": null, \"beta\": 0.5, \"outer\": [],\n\"points\": [[" +
               x + ", " + y + "], [" + y + "," + x +
               "]]}, {\"points\": [[1, 2], [3, 2], [3, 5]], \"closed\": " +
               "true, \"outer\": [\"a\"]}]}";
    };
    auto bits = [](double v) {
        std::uint64_t b = 0;
        std::memcpy(&b, &v, sizeof b);
        return b;
    };
    for (const std::string& x : numbers)
        for (const std::string& y : {std::string("7"), std::string("-1e-5")}) {
            INFO(x << " " << y);
            const Scene direct = parse_scene_json(text(x, y, false), "direct.json");
            const Scene sax = parse_scene_json(text(x, y, true), "sax.json");
            REQUIRE(direct.metadata.empty());
            REQUIRE(sax.metadata.size() == 1);
            REQUIRE(direct.size() == sax.size());
            REQUIRE(direct.units() == sax.units());
            for (std::size_t i = 0; i < direct.size(); ++i) {
                const Layer& a = direct.layer(i);
                const Layer& b = sax.layer(i);
                REQUIRE(a.name == b.name);
                REQUIRE(a.closed == b.closed);
                REQUIRE(bits(a.thickness) == bits(b.thickness));
                REQUIRE(bits(a.weight) == bits(b.weight));
                REQUIRE(a.alpha == b.alpha);
                REQUIRE(a.beta == b.beta);
                REQUIRE(a.outer == b.outer);
                REQUIRE(a.points.size() == b.points.size());
                for (std::size_t k = 0; k < a.points.size(); ++k) {
                    REQUIRE(bits(a.points[k].x) == bits(b.points[k].x));
                    REQUIRE(bits(a.points[k].y) == bits(b.points[k].y));
                }
            }
        }
    // What the direct reader gives up on still reads (or fails) as before.
    for (const char* odd :
         {R"({"layers": [{"points": [[1, 2], [3, 4]], "name": "a\u00e9"}]})",
          R"({"layers": [{"points": [[1, 2], [3, 4]], "name": "é"}]})",
          R"({"layers": [{"points": [[1, 2], [3, 4]], "points": [[3, 4], [5, 6]]}]})"})
        REQUIRE_NOTHROW(parse_scene_json(odd, "odd.json"));
    for (const char* bad : {R"({"layers": [{"points": [[01, 2], [3, 4]]}]})",
                            R"({"layers": [{"points": [[1., 2], [3, 4]]}]})",
                            R"({"layers": [{"points": [[1, 2], [3, 4]]}]} x)",
                            R"({"strata": 1.0, "layers": [{"points": [[1, 2], [3, 4]]}]})"})
        REQUIRE_THROWS_AS(parse_scene_json(bad, "bad.json"), InvalidInput);
}
