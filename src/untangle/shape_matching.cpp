#include "strata/untangle/shape_matching.h"

#include "strata/core/error.h"
#include "strata/core/format.h"

#include <Eigen/Dense>
#include <glm/geometric.hpp>

#include <cmath>
#include <string>

namespace strata {

void validate(const ShapeMatchParams& params) {
    auto in_unit = [](const char* field, double value, bool open) {
        const bool ok = open ? (value > 0.0 && value < 1.0) : (value >= 0.0 && value <= 1.0);
        if (!ok)
            throw InvalidInput(std::string("shape_match: params.") + field + " must be in " +
                               (open ? "(0, 1)" : "[0, 1]") + " (got " + format_number(value) +
                               ")");
    };
    in_unit("alpha", params.alpha, false);
    in_unit("beta", params.beta, false);
    in_unit("rank_tolerance", params.rank_tolerance, true);
}

ShapeMatchReport shape_match(const std::vector<Vec2>& rest, std::vector<Vec2>& current,
                             const std::vector<double>& masses, const std::vector<char>& fixed,
                             const ShapeMatchParams& params) {
    validate(params);
    const std::size_t n = rest.size();
    if (current.size() != n || (!masses.empty() && masses.size() != n) ||
        (!fixed.empty() && fixed.size() != n))
        throw InvalidInput(
            "shape_match: rest, current, masses and fixed must have the same size (got " +
            std::to_string(n) + ", " + std::to_string(current.size()) + ", " +
            std::to_string(masses.size()) + ", " + std::to_string(fixed.size()) + ")");
    ShapeMatchReport report;
    if (n == 0) return report;
    auto mass = [&](std::size_t i) { return masses.empty() ? 1.0 : masses[i]; };
    double total = 0.0;
    Vec2 rest_cm(0.0), cm(0.0);
    for (std::size_t i = 0; i < n; ++i) {
        const double m = mass(i);
        if (!(m > 0.0) || !std::isfinite(m))
            throw InvalidInput("shape_match: masses[" + std::to_string(i) + "] must be > 0 (got " +
                               format_number(m) + ")");
        total += m;
        rest_cm += m * rest[i];
        cm += m * current[i];
    }
    rest_cm /= total;
    cm /= total;

    // Piece size, to scale q for the quadratic terms.
    double size = 0.0;
    for (std::size_t i = 0; i < n; ++i) size = std::max(size, glm::length(rest[i] - rest_cm));
    if (!(size > 0.0)) {  // all rest points coincide: only the translation is defined.
        for (std::size_t i = 0; i < n; ++i)
            if (fixed.empty() || !fixed[i])
                current[i] = (1.0 - params.alpha) * current[i] + params.alpha * cm;
        return report;
    }

    Eigen::Matrix2d apq = Eigen::Matrix2d::Zero();
    Eigen::Matrix<double, 2, 5> apq5 = Eigen::Matrix<double, 2, 5>::Zero();
    Eigen::Matrix<double, 5, 5> aqq5 = Eigen::Matrix<double, 5, 5>::Zero();
    // q~ with its quadratic part centred (weighted mean removed): p has zero mean, so without
    // the centring a quadratic deformation could not be fitted exactly (no constant term).
    std::vector<Eigen::Matrix<double, 5, 1>> qt(n);
    Eigen::Matrix<double, 5, 1> mean = Eigen::Matrix<double, 5, 1>::Zero();
    for (std::size_t i = 0; i < n; ++i) {
        const Vec2 q = (rest[i] - rest_cm) / size;
        qt[i] << q.x, q.y, q.x * q.x, q.y * q.y, q.x * q.y;
        mean += mass(i) * qt[i];
    }
    mean /= total;
    mean.head<2>().setZero();  // exactly zero already, up to rounding
    for (std::size_t i = 0; i < n; ++i) {
        const double m = mass(i);
        qt[i] -= mean;
        const Vec2 q(qt[i](0), qt[i](1));
        const Vec2 p = current[i] - cm;
        const Eigen::Vector2d pe(p.x, p.y);
        apq += m * pe * Eigen::Vector2d(q.x, q.y).transpose();
        apq5 += m * pe * qt[i].transpose();
        aqq5 += m * qt[i] * qt[i].transpose();
    }
    // Closest rotation to A_pq (maximises tr(R^T A_pq)); always det +1.
    const double angle = std::atan2(apq(1, 0) - apq(0, 1), apq(0, 0) + apq(1, 1));
    report.rotation = angle;
    Eigen::Matrix2d rot;
    rot << std::cos(angle), -std::sin(angle), std::sin(angle), std::cos(angle);
    Eigen::Matrix<double, 2, 5> rigid = Eigen::Matrix<double, 2, 5>::Zero();
    rigid.leftCols<2>() = size * rot;  // q~ holds q / size

    // Pseudo-inverse of the symmetric moment matrix.
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 5, 5>> eigen(aqq5);
    const Eigen::Matrix<double, 5, 1> values = eigen.eigenvalues();
    const double largest = values.maxCoeff();
    Eigen::Matrix<double, 5, 1> inverse = Eigen::Matrix<double, 5, 1>::Zero();
    int rank = 0;
    for (int k = 0; k < 5; ++k)
        if (values(k) > params.rank_tolerance * largest) {
            inverse(k) = 1.0 / values(k);
            ++rank;
        }
    const Eigen::Matrix<double, 5, 5> pinv =
        eigen.eigenvectors() * inverse.asDiagonal() * eigen.eigenvectors().transpose();
    const Eigen::Matrix<double, 2, 5> quadratic = apq5 * pinv;
    report.quadratic_rank = rank;

    double beta = params.beta;
    // The barycentre takes one point's worth of freedom; the fit interpolates when the
    // remaining points are no more than the fitted modes.
    const double r = static_cast<double>(rank), count = static_cast<double>(n) - 1.0;
    if (count <= r)
        beta = 0.0;
    else if (count < 2.0 * r)
        beta *= (count - r) / r;
    report.beta_used = beta;

    const Eigen::Matrix<double, 2, 5> blend = beta * quadratic + (1.0 - beta) * rigid;
    for (std::size_t i = 0; i < n; ++i) {
        if (!fixed.empty() && fixed[i]) continue;
        const Eigen::Vector2d g = blend * qt[i];
        const Vec2 goal = Vec2(g(0), g(1)) + cm;
        current[i] = (1.0 - params.alpha) * current[i] + params.alpha * goal;
    }
    return report;
}

}  // namespace strata
