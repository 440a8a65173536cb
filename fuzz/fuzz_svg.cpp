// Fuzz target: the SVG reader (parse_scene_svg). Any text either parses or throws
// InvalidInput; a parsed scene writes back to SVG that parses to as many layers with as many
// points, and the exact check runs on it without crashing.
#include "check.h"
#include "strata/core/error.h"
#include "strata/geometry/checks.h"
#include "strata/io/svg_io.h"

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    strata::Scene scene;
    try {
        scene = strata::parse_scene_svg(text, "fuzz.svg");
    } catch (const strata::InvalidInput&) {
        return 0;
    }
    std::string written;
    try {
        written = strata::scene_to_svg(scene);
    } catch (const strata::InvalidInput& e) {
        std::fprintf(stderr, "%s\n", e.what());
        FUZZ_CHECK(false, "a parsed scene cannot be written as SVG");
    }
    strata::Scene again;
    try {
        again = strata::parse_scene_svg(written, "rewritten.svg");
    } catch (const strata::InvalidInput& e) {
        std::fprintf(stderr, "%s\n", e.what());
        FUZZ_CHECK(false, "the SVG written for a parsed scene does not parse");
    }
    FUZZ_CHECK(again.size() == scene.size(), "round trip changed the layer count");
    for (std::size_t i = 0; i < scene.size(); ++i) {
        FUZZ_CHECK(again.layer(i).name == scene.layer(i).name, "round trip changed a name");
        FUZZ_CHECK(again.layer(i).closed == scene.layer(i).closed, "round trip changed closed");
        FUZZ_CHECK(again.layer(i).points.size() == scene.layer(i).points.size(),
                   "round trip changed a point count");
    }
    if (scene.vertex_count() <= 4000) {
        try {
            (void)strata::check_scene(scene);
        } catch (const strata::InvalidInput&) {
        }
    }
    return 0;
}
