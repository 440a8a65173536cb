#include "strata/untangle/localize.h"

#include <algorithm>

namespace strata {

namespace {

// Pieces of one layer from its inside flags.
void layer_pieces(std::size_t layer_index, const Layer& layer, const std::vector<char>& inside,
                  std::size_t n_out, std::vector<Piece>& out) {
    const std::size_t n = layer.points.size();
    // Mark the vertices covered by a run or its collar.
    std::vector<char> covered(n, 0);
    bool any = false;
    for (std::size_t i = 0; i < n; ++i) {
        if (!inside[i]) continue;
        any = true;
        for (std::size_t k = 0; k <= n_out && k < n; ++k) {
            if (layer.closed) {
                covered[(i + k) % n] = 1;
                covered[(i + n - k) % n] = 1;
            } else {
                if (i + k < n) covered[i + k] = 1;
                if (k <= i) covered[i - k] = 1;
            }
        }
    }
    if (!any) return;
    const auto count = static_cast<std::size_t>(std::count(covered.begin(), covered.end(), 1));
    if (layer.closed && count == n) {
        Piece piece;
        piece.layer = layer_index;
        piece.is_whole_loop = true;
        for (std::size_t i = 0; i < n; ++i) {
            piece.vertices.push_back(i);
            piece.is_free.push_back(inside[i]);
        }
        out.push_back(std::move(piece));
        return;
    }
    // Start after an uncovered vertex so that a closed layer's wrapping run stays whole.
    std::size_t start = 0;
    if (layer.closed)
        while (covered[start]) ++start;
    Piece piece;
    piece.layer = layer_index;
    for (std::size_t k = 0; k < n; ++k) {
        const std::size_t i = (start + k) % n;
        if (covered[i]) {
            piece.vertices.push_back(i);
            piece.is_free.push_back(inside[i]);
        } else if (!piece.vertices.empty()) {
            out.push_back(std::move(piece));
            piece = Piece{};
            piece.layer = layer_index;
        }
    }
    if (!piece.vertices.empty()) out.push_back(std::move(piece));
}

}  // namespace

std::vector<Piece> localize(const Scene& scene, const Box2& box, std::size_t n_out) {
    std::vector<Piece> pieces;
    for (std::size_t l = 0; l < scene.size(); ++l) {
        const Layer& layer = scene.layer(l);
        if (!layer.bounds().overlaps(box)) continue;
        std::vector<char> inside(layer.points.size());
        for (std::size_t i = 0; i < layer.points.size(); ++i)
            inside[i] = box.contains(layer.points[i]);
        const std::size_t first = pieces.size();
        layer_pieces(l, layer, inside, n_out, pieces);
        std::sort(
            pieces.begin() + static_cast<std::ptrdiff_t>(first), pieces.end(),
            [](const Piece& a, const Piece& b) { return a.vertices.front() < b.vertices.front(); });
    }
    return pieces;
}

std::vector<Piece> whole_scene_pieces(const Scene& scene) {
    std::vector<Piece> pieces;
    for (std::size_t l = 0; l < scene.size(); ++l) {
        Piece piece;
        piece.layer = l;
        piece.is_whole_loop = scene.layer(l).closed;
        const std::size_t n = scene.layer(l).points.size();
        for (std::size_t i = 0; i < n; ++i) piece.vertices.push_back(i);
        piece.is_free.assign(n, 1);
        pieces.push_back(std::move(piece));
    }
    return pieces;
}

}  // namespace strata
