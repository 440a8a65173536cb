// Fuzz target: the layer JSON reader (parse_scene_json). Any text either parses or throws
// InvalidInput; a parsed scene writes back to JSON that parses to the same scene, and the
// exact check runs on it without crashing.
#include "check.h"
#include "strata/core/error.h"
#include "strata/geometry/checks.h"
#include "strata/io/json_io.h"

#include <cstddef>
#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    strata::Scene scene;
    try {
        scene = strata::parse_scene_json(text, "fuzz.json");
    } catch (const strata::InvalidInput&) {
        return 0;
    }
    const std::string written = strata::scene_to_json(scene);
    strata::Scene again;
    try {
        again = strata::parse_scene_json(written, "rewritten.json");
    } catch (const strata::InvalidInput& e) {
        std::fprintf(stderr, "%s\n", e.what());
        FUZZ_CHECK(false, "the JSON written for a parsed scene does not parse");
    }
    FUZZ_CHECK(again.size() == scene.size(), "round trip changed the layer count");
    for (std::size_t i = 0; i < scene.size(); ++i) {
        const strata::Layer& a = scene.layer(i);
        const strata::Layer& b = again.layer(i);
        FUZZ_CHECK(a.name == b.name && a.closed == b.closed, "round trip changed a layer");
        FUZZ_CHECK(a.points.size() == b.points.size(), "round trip changed a point count");
        for (std::size_t k = 0; k < a.points.size(); ++k)
            FUZZ_CHECK(a.points[k] == b.points[k], "round trip changed a point");
        FUZZ_CHECK(a.thickness == b.thickness && a.weight == b.weight,
                   "round trip changed a thickness or weight");
    }
    if (scene.vertex_count() <= 4000) {
        try {
            (void)strata::check_scene(scene);
        } catch (const strata::InvalidInput&) {
        }
    }
    return 0;
}
