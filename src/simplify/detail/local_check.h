#pragma once
/// @file The exact local test of the simplification driver: a removal, or the result of an
/// untangling job, keeps the region around it collision-free (no crossing, every separation,
/// nesting kept, closed layers not flat). It reads positions through an Overlay and looks only
/// at the segments near the change, so that its cost does not grow with the scene. Private to
/// src/simplify.

#include "simplify/detail/live_polylines.h"
#include "simplify/detail/separations.h"
#include "simplify/detail/untangle_job.h"
#include "strata/geometry/input_sides.h"
#include "strata/geometry/scene.h"

#include <cstddef>
#include <vector>

namespace strata::detail {

class LocalCheck {
  public:
    /// `outside_signs`: outside_side() of every layer of `input`; `sides`: the input's sides
    /// (record_input_sides(input)), by input vertex id. Both read only by the checks over a
    /// job. Keeps references to every argument.
    LocalCheck(const Scene& input, const LivePolylines& live, const Separations& separations,
               const std::vector<int>& outside_signs, const InputSides& sides);

    /// The removal of the vertex at `removed` between a and b (unlinked) of layer l: layer l
    /// stays valid, the closed triangle (a, removed, b) holds no other vertex, and the chord
    /// (a, b) meets nothing and keeps its separations.
    bool removal_clear(std::size_t l, std::size_t a, const Vec2& removed, std::size_t b,
                       const Overlay& ov) const;
    /// Segment (a, b) of layer l meets no other segment and keeps its separations.
    bool segment_clear(std::size_t l, std::size_t a, std::size_t b, const Overlay& ov) const;
    /// Layer l, if closed and down to 3 vertices, is not flat.
    bool closed_valid(std::size_t l, const Overlay& ov) const;
    /// Over a job: every vertex of `ids` (layer l) stays on its side of every closed layer.
    bool nesting_kept(std::size_t l, const std::vector<std::size_t>& ids, const Overlay& ov) const;
    /// Over a job: every vertex it moves is on the side of each open layer under or over its
    /// own that the input gives it (`sides`), or that the global order asks for where the
    /// input gives none, as check_scene() judges it (the side at the closest point within the
    /// near distance of the input, automatic_near_distance()). A vertex carried around the end
    /// of an open layer crosses nothing; this is what catches it. The end vertices of the
    /// open layers within that distance of the job are tested too, moved or not. Not checked
    /// here: another vertex the job does not move whose closest point moves with an open layer
    /// (scanning every vertex within the near distance of the moved segments took 44 of 49 CPU
    /// seconds of a 1M-vertex stack at 95%); the final whole-scene check still judges every
    /// vertex.
    bool sides_kept(const Overlay& ov) const;

  private:
    /// The closest segment of one layer to a point, within reach_.
    struct Closest {
        double best = 0.0;  ///< Its distance.
        std::size_t seg = kNone;
        Vec2 point{0.0};  ///< The closest point.
    };
    /// A segment of an open layer at the overlay's positions, with its box.
    struct NearSegment {
        std::size_t start = 0;
        Vec2 a{0.0}, b{0.0};
        Box2 box;
    };
    /// near[k]: the segments of open layer k (one under or over another layer) whose boxes
    /// meet `box`, at the overlay's positions (zero-length ones left out).
    void segments_near(const Box2& box, const Overlay& ov,
                       std::vector<std::vector<NearSegment>>& near) const;
    /// The closest of `segments` (one layer's, segments_near() of a box holding p inflated by
    /// reach_) to p, as check_scene() finds it: the smallest segment index among equally close
    /// ones, nothing (seg kNone) farther than reach_.
    Closest closest_of(const Vec2& p, const std::vector<NearSegment>& segments) const;
    /// check_scene()'s side of open layer k at p, given its closest segment (0: nothing
    /// closer than reach_, closest to an end, or on the layer).
    int side_of_closest(std::size_t k, const Vec2& p, const Closest& c, const Overlay& ov) const;
    /// Vertex x of layer j, at its overlay position, is on its wanted side of every open layer
    /// k it nests with. `near`: segments_near() of a box holding it inflated by reach_.
    bool keeps_sides(std::size_t j, std::size_t x, const Overlay& ov,
                     const std::vector<std::vector<NearSegment>>& near) const;
    bool on_wanted_side(std::size_t k, std::size_t l, const Vec2& pa, const Vec2& pb,
                        const Vec2& w) const;
    /// Segment (a, b) of layer l at its overlay positions p, q, and their box.
    struct Chord {
        std::size_t l, a, b;
        Vec2 p, q;
        Box2 box;
    };
    Chord chord_of(std::size_t l, std::size_t a, std::size_t b, const Overlay& ov) const;
    /// Segment (k, u) meets the chord nowhere and keeps its separation from it.
    bool clear_of_chord(const Chord& c, std::size_t k, std::size_t u, const Overlay& ov) const;
    /// clear_of_chord() given the segment: from u to u2 (its next alive vertex), at s0, s1.
    bool chord_clear_of(const Chord& c, std::size_t k, std::size_t u, std::size_t u2,
                        const Vec2& s0, const Vec2& s1) const;
    /// The closed triangle (pa, removed, pb) of a removal between a and b of layer l, its box.
    struct Triangle {
        std::size_t l, a, b;
        Vec2 pa, removed, pb;
        Box2 box;
    };
    bool clear_of_triangle(const Triangle& t, std::size_t k, std::size_t u,
                           const Overlay& ov) const;
    /// clear_of_triangle() given the segment: from u to u2 at s0, s1; u2_is_last: u2 is the
    /// last vertex of an open layer. `ov`: the overlay of a job (or none).
    bool triangle_clear_of(const Triangle& t, std::size_t k, std::size_t u, std::size_t u2,
                           bool u2_is_last, const Vec2& s0, const Vec2& s1,
                           const Overlay* ov = nullptr) const;
    void changed_segments(std::size_t k, const Overlay& ov, std::vector<Vec2>& olds,
                          std::vector<Vec2>& news) const;

    const Scene& input_;
    const LivePolylines& live_;
    const Separations& separations_;
    const std::vector<int>& outside_signs_;
    const InputSides& sides_;
    double reach_ = 0.0;         // check_scene()'s automatic near distance of the input
    bool open_nesting_ = false;  // some open layer is under or over another layer
    std::vector<char> open_under_over_;     // per layer: open, another layer under or over it
    std::vector<char> under_or_over_open_;  // per layer: under or over an open layer
};

}  // namespace strata::detail
