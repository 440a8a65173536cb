#include "field/detail/segment_store.h"

#include "strata/core/error.h"
#include "strata/core/format.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <string>

namespace strata::detail {

namespace {

constexpr std::size_t kSpareSlots = 64;  // more than any local edit needs at once

double cross(const Vec2& a, const Vec2& b) {
    return a.x * b.y - a.y * b.x;
}

Vec2 unit_or_zero(const Vec2& v) {
    const double len = std::sqrt(v.x * v.x + v.y * v.y);
    return len > 0.0 ? v / len : Vec2(0.0);
}

}  // namespace

void check_points(const std::vector<Vec2>& points, bool closed, const char* where) {
    const std::size_t need = closed ? 3 : 2;
    if (points.size() < need)
        throw InvalidInput(std::string(where) + ": a " + (closed ? "closed" : "open") +
                           " layer needs at least " + std::to_string(need) + " points (got " +
                           std::to_string(points.size()) + ")");
    for (std::size_t i = 0; i < points.size(); ++i)
        if (!std::isfinite(points[i].x) || !std::isfinite(points[i].y))
            throw InvalidInput(std::string(where) + ": point " + std::to_string(i) +
                               " is not finite (" + format_number(points[i].x) + ", " +
                               format_number(points[i].y) + ")");
}

bool beats(double dist2, const Segment& s, std::uint32_t slot, const Nearest& best,
           const std::vector<Segment>& segments) {
    if (dist2 != best.dist2) return dist2 < best.dist2;
    if (!best.found()) return true;
    const Segment& o = segments[best.slot];
    if (s.a.x != o.a.x) return s.a.x < o.a.x;
    if (s.a.y != o.a.y) return s.a.y < o.a.y;
    if (s.b.x != o.b.x) return s.b.x < o.b.x;
    if (s.b.y != o.b.y) return s.b.y < o.b.y;
    return slot < best.slot;
}

Segment SegmentStore::make_segment(const std::vector<Vec2>& points, std::size_t i) const {
    const std::size_t n = points.size();
    const std::size_t segs = closed_ ? n : n - 1;
    const auto normal_of = [&](std::size_t k) {
        const Vec2 d = points[(k + 1) % n] - points[k];
        return static_cast<double>(outside_sign_) * unit_or_zero(Vec2(d.y, -d.x));
    };
    Segment s;
    s.live = true;
    s.a = points[i];
    s.b = points[(i + 1) % n];
    s.normal = normal_of(i);
    if (!closed_ && i == 0) {
        s.a_is_end = true;
    } else {
        s.pseudo_a = s.normal + normal_of((i + segs - 1) % segs);
    }
    if (!closed_ && i + 1 == segs) {
        s.b_is_end = true;
    } else {
        s.pseudo_b = s.normal + normal_of((i + 1) % segs);
    }
    return s;
}

void SegmentStore::update_ends(const std::vector<Vec2>& points) {
    if (closed_) return;
    const std::size_t n = points.size();
    end_c_[0] = points[0];
    end_t_[0] = unit_or_zero(points[0] - points[1]);
    end_c_[1] = points[n - 1];
    end_t_[1] = unit_or_zero(points[n - 1] - points[n - 2]);
}

void SlotSequence::assign(std::size_t n) {
    blocks_.clear();
    size_ = n;
    for (std::size_t first = 0; first < n; first += kBlock) {
        std::vector<std::uint32_t>& block = blocks_.emplace_back(std::min(kBlock, n - first));
        for (std::size_t k = 0; k < block.size(); ++k)
            block[k] = static_cast<std::uint32_t>(first + k);
    }
    rebuild_sums();
}

void SlotSequence::rebuild_sums() {
    const std::size_t count = blocks_.size();
    sums_.assign(count + 1, 0);
    for (std::size_t i = 1; i <= count; ++i) {
        sums_[i] += blocks_[i - 1].size();
        const std::size_t parent = i + (i & (~i + 1));
        if (parent <= count) sums_[parent] += sums_[i];
    }
}

void SlotSequence::add_to_sums(std::size_t block, std::size_t count) {
    for (std::size_t i = block + 1; i < sums_.size(); i += i & (~i + 1)) sums_[i] += count;
}

void SlotSequence::remove_from_sums(std::size_t block, std::size_t count) {
    for (std::size_t i = block + 1; i < sums_.size(); i += i & (~i + 1)) sums_[i] -= count;
}

void SlotSequence::locate(std::size_t k, std::size_t& block, std::size_t& offset) const {
    const std::size_t count = blocks_.size();
    std::size_t step = 1;
    while (2 * step <= count) step *= 2;
    std::size_t pos = 0, rest = k;
    for (; step > 0; step /= 2)
        if (pos + step <= count && sums_[pos + step] <= rest) {
            pos += step;
            rest -= sums_[pos];
        }
    // pos blocks hold at most k entries; pos == count only for k == size().
    if (pos == count && count > 0) {
        block = count - 1;
        offset = blocks_[block].size();
    } else {
        block = pos;
        offset = rest;
    }
}

void SlotSequence::read(std::size_t first, std::size_t count,
                        std::vector<std::uint32_t>& out) const {
    out.clear();
    if (count == 0) return;
    std::size_t b = 0, off = 0;
    locate(first, b, off);
    while (out.size() < count) {
        out.push_back(blocks_[b][off]);
        if (++off == blocks_[b].size()) {
            ++b;
            off = 0;
        }
    }
}

void SlotSequence::replace(std::size_t first, std::size_t count,
                           const std::vector<std::uint32_t>& values) {
    std::size_t b = 0, off = 0;
    if (count > 0) locate(first, b, off);
    bool reshaped = false;
    for (std::size_t left = count; left > 0;) {
        std::vector<std::uint32_t>& block = blocks_[b];
        const std::size_t m = std::min(left, block.size() - off);
        const auto at = block.begin() + static_cast<std::ptrdiff_t>(off);
        block.erase(at, at + static_cast<std::ptrdiff_t>(m));
        left -= m;
        size_ -= m;
        if (block.empty()) {
            blocks_.erase(blocks_.begin() + static_cast<std::ptrdiff_t>(b));
            reshaped = true;
        } else {
            if (!reshaped) remove_from_sums(b, m);
            if (off == block.size()) {
                ++b;
                off = 0;
            }
        }
    }
    if (reshaped) rebuild_sums();
    if (values.empty()) return;
    if (blocks_.empty()) {
        blocks_.emplace_back();
        rebuild_sums();
    }
    locate(first, b, off);
    std::vector<std::uint32_t>& block = blocks_[b];
    block.insert(block.begin() + static_cast<std::ptrdiff_t>(off), values.begin(), values.end());
    size_ += values.size();
    if (block.size() > 2 * kBlock) {
        const auto half = block.begin() + static_cast<std::ptrdiff_t>(block.size() / 2);
        std::vector<std::uint32_t> tail(half, block.end());
        block.erase(half, block.end());
        blocks_.insert(blocks_.begin() + static_cast<std::ptrdiff_t>(b + 1), std::move(tail));
        rebuild_sums();
    } else {
        add_to_sums(b, values.size());
    }
}

std::size_t SlotSequence::memory_bytes() const {
    std::size_t bytes = blocks_.capacity() * sizeof(std::vector<std::uint32_t>) +
                        sums_.capacity() * sizeof(std::size_t);
    for (const auto& block : blocks_) bytes += block.capacity() * sizeof(std::uint32_t);
    return bytes;
}

std::uint32_t SegmentStore::allocate() {
    if (!free_.empty()) {
        const std::uint32_t slot = free_.back();
        free_.pop_back();
        return slot;
    }
    segments_.emplace_back();
    return static_cast<std::uint32_t>(segments_.size() - 1);
}

void SegmentStore::build(const std::vector<Vec2>& points, bool closed, int outside_sign) {
    closed_ = closed;
    const std::size_t n = points.size();
    const std::size_t segs = closed ? n : n - 1;
    twice_area_ = 0.0;
    if (closed) {
        for (std::size_t i = 0; i < n; ++i) twice_area_ += cross(points[i], points[(i + 1) % n]);
        // Counter-clockwise: the inside is on the left, so the outside is on the right (+1).
        outside_sign_ = twice_area_ >= 0.0 ? 1 : -1;
    } else {
        outside_sign_ = outside_sign;
    }
    segments_.clear();
    free_.clear();
    slot_of_.assign(segs);
    // Headroom: an edit allocates the new slots before it frees the old ones (their geometry is
    // read afterwards), so without it the first edit after a build would copy every segment.
    segments_.reserve(segs + kSpareSlots);
    for (std::size_t i = 0; i < segs; ++i) segments_.push_back(make_segment(points, i));
    update_ends(points);
}

bool SegmentStore::splice(const std::vector<Vec2>& points, const PolylineEdit& edit,
                          std::vector<std::uint32_t>& removed, std::vector<std::uint32_t>& added) {
    removed.clear();
    added.clear();
    const std::size_t n_old = closed_ ? slot_of_.size() : slot_of_.size() + 1;
    const std::size_t n_new = points.size();
    if (edit.first + edit.removed > n_old || n_new + edit.removed != n_old + edit.inserted ||
        edit.first + edit.inserted > n_new)
        throw InvalidInput("LayerField::update: edit {first " + std::to_string(edit.first) +
                           ", removed " + std::to_string(edit.removed) + ", inserted " +
                           std::to_string(edit.inserted) + "} does not fit " +
                           std::to_string(n_old) + " old and " + std::to_string(n_new) +
                           " new points");
    // Only the edited points are checked: the others are the caller's unchanged ones, and a
    // scan of the whole polyline would make the update cost grow with the layer.
    if (n_new < (closed_ ? 3u : 2u))
        throw InvalidInput("LayerField::update: too few points (" + std::to_string(n_new) + ")");
    for (std::size_t i = edit.first; i < edit.first + edit.inserted; ++i)
        if (!std::isfinite(points[i].x) || !std::isfinite(points[i].y))
            throw InvalidInput("LayerField::update: point " + std::to_string(i) +
                               " is not finite (" + format_number(points[i].x) + ", " +
                               format_number(points[i].y) + ")");
    if (edit.removed == 0 && edit.inserted == 0) return true;

    const auto full = [&] {
        build(points, closed_, outside_sign_);
        return false;
    };
    if (n_old < 8 || n_new < 8) return full();
    const long segs_old = static_cast<long>(closed_ ? n_old : n_old - 1);
    const long segs_new = static_cast<long>(closed_ ? n_new : n_new - 1);
    long lo = static_cast<long>(edit.first) - 2;
    long hi_old = static_cast<long>(edit.first + edit.removed);
    long hi_new = static_cast<long>(edit.first + edit.inserted);
    if (closed_) {
        if (lo < 0 || hi_old > segs_old - 1 || hi_new > segs_new - 1) return full();
    } else {
        lo = std::max(lo, 0L);
        hi_old = std::min(hi_old, segs_old - 1);
        hi_new = std::min(hi_new, segs_new - 1);
    }
    std::vector<std::uint32_t> old_slots;
    slot_of_.read(static_cast<std::size_t>(lo), static_cast<std::size_t>(hi_old - lo + 1),
                  old_slots);
    if (closed_) {
        double area = twice_area_;
        const auto n = points.size();
        for (const std::uint32_t slot : old_slots) {
            const Segment& s = segments_[slot];
            area -= cross(s.a, s.b);
        }
        for (long k = lo; k <= hi_new; ++k) {
            const auto i = static_cast<std::size_t>(k);
            area += cross(points[i], points[(i + 1) % n]);
        }
        if ((area >= 0.0 ? 1 : -1) != outside_sign_) return full();
        twice_area_ = area;
    }
    for (long k = lo; k <= hi_new; ++k) {
        const std::uint32_t slot = allocate();
        segments_[slot] = make_segment(points, static_cast<std::size_t>(k));
        added.push_back(slot);
    }
    for (const std::uint32_t slot : old_slots) {
        segments_[slot].live = false;
        removed.push_back(slot);
    }
    slot_of_.replace(static_cast<std::size_t>(lo), old_slots.size(), added);
    free_.insert(free_.end(), removed.begin(), removed.end());
    update_ends(points);
    return true;
}

double SegmentStore::border(const Vec2& x) const {
    if (closed_) return std::numeric_limits<double>::infinity();
    const Vec2 d0 = x - end_c_[0], d1 = x - end_c_[1];
    const int e = glm::dot(d1, d1) < glm::dot(d0, d0) ? 1 : 0;
    return glm::dot(end_c_[e] - x, end_t_[e]);
}

FieldSample SegmentStore::evaluate(const Vec2& x, const Nearest& n) const {
    FieldSample out;
    out.border = border(x);
    const Segment& s = segments_[n.slot];
    const double dist = std::sqrt(n.dist2);
    if (n.t > 0.0 && n.t < 1.0) {
        const double side = glm::dot(x - s.a, s.normal);
        out.value = side >= 0.0 ? dist : -dist;
        out.gradient = s.normal;
        return out;
    }
    const bool at_a = n.t <= 0.0;
    const Vec2 v = at_a ? s.a : s.b;
    if (at_a ? s.a_is_end : s.b_is_end) {
        out.value = glm::dot(x - v, s.normal);
        out.gradient = s.normal;
        out.past_end = true;
        return out;
    }
    Vec2 pn = at_a ? s.pseudo_a : s.pseudo_b;
    if (glm::dot(pn, pn) == 0.0) pn = s.normal;
    const double sign = glm::dot(x - v, pn) >= 0.0 ? 1.0 : -1.0;
    out.value = sign * dist;
    out.gradient = dist > 0.0 ? sign * (x - v) / dist : unit_or_zero(pn);
    return out;
}

}  // namespace strata::detail
