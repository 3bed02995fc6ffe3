#include "passes/PatternPaths.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace stepnc::passes {

namespace {

using geom::Seg;
using geom::Vec2;

constexpr double kPi = std::numbers::pi;

/// Five-point Gauss-Legendre nodes and weights on [-1, 1].
constexpr double kNodes[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831, 0.9061798459386640};
constexpr double kWeights[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665,
                                0.2369268850561891};
/// Largest angle (rad) of arc one quadrature interval spans: five points
/// integrate a sine times a line over it to about 1e-13 of its size.
constexpr double kArcPiece = 0.25;

/// Arc lengths at the starts of a chain's segments, and its total length.
std::vector<double> startsOf(const std::vector<Seg> &chain, double &length) {
  std::vector<double> starts;
  starts.reserve(chain.size());
  length = 0;
  for (const Seg &s : chain) {
    starts.push_back(length);
    length += s.length();
  }
  return starts;
}

/// The point of `chain` at arc length s in [0, length].
Vec2 pointAt(const std::vector<Seg> &chain, const std::vector<double> &starts, double s) {
  size_t i = size_t(std::upper_bound(starts.begin(), starts.end(), s) - starts.begin());
  i = i == 0 ? 0 : i - 1;
  const double len = chain[i].length();
  return chain[i].at(len > 0 ? std::clamp((s - starts[i]) / len, 0.0, 1.0) : 0.0);
}

/// Integral of (alpha + beta u) du over [u0, u1].
double weightIntegral(double u0, double u1, double alpha, double beta) {
  return alpha * (u1 - u0) + beta * (u1 * u1 - u0 * u0) / 2;
}

} // namespace

SmoothGuide::SmoothGuide(std::vector<Seg> chain, double halfWidth) : segs_(std::move(chain)), w_(halfWidth) {
  start_ = startsOf(segs_, length_);
}

Vec2 SmoothGuide::raw(double s) const { return pointAt(segs_, start_, std::clamp(s, 0.0, length_)); }

Vec2 SmoothGuide::weighted(double u0, double u1, double alpha, double beta) const {
  Vec2 sum = Vec2::Zero();
  size_t i = size_t(std::upper_bound(start_.begin(), start_.end(), u0) - start_.begin());
  i = i == 0 ? 0 : i - 1;
  for (; i < segs_.size() && start_[i] < u1; ++i) {
    const Seg &seg = segs_[i];
    const double len = seg.length();
    const double a = std::max(u0, start_[i]), b = std::min(u1, start_[i] + len);
    if (b <= a || len <= 0)
      continue;
    // Lines: the integrand is a quadratic, which the rule integrates exactly
    // in one interval; arcs: intervals of at most kArcPiece radians.
    const int pieces = seg.isArc() ? std::max(1, int(std::ceil((b - a) / seg.radius() / kArcPiece))) : 1;
    const double h = (b - a) / pieces;
    for (int k = 0; k < pieces; ++k) {
      const double mid = a + h * (k + 0.5);
      for (int q = 0; q < 5; ++q) {
        const double u = mid + h / 2 * kNodes[q];
        sum += (kWeights[q] * h / 2 * (alpha + beta * u)) * seg.at(std::clamp((u - start_[i]) / len, 0.0, 1.0));
      }
    }
  }
  return sum;
}

Vec2 SmoothGuide::at(double s) const {
  const double w2 = w_ * w_;
  // Left half of the kernel: weight (u - s + w) / w^2; right half: (s + w - u) / w^2.
  const struct {
    double lo, hi, alpha, beta;
  } halves[2] = {{s - w_, s, (w_ - s) / w2, 1 / w2}, {s, s + w_, (s + w_) / w2, -1 / w2}};
  Vec2 sum = Vec2::Zero();
  const Vec2 first = segs_.front().a, last = segs_.back().b;
  for (const auto &h : halves) {
    // Before the chain C stays at its start, after it at its end.
    if (h.lo < 0)
      sum += weightIntegral(h.lo, std::min(h.hi, 0.0), h.alpha, h.beta) * first;
    if (h.hi > length_)
      sum += weightIntegral(std::max(h.lo, length_), h.hi, h.alpha, h.beta) * last;
    const double a = std::max(h.lo, 0.0), b = std::min(h.hi, length_);
    if (b > a)
      sum += weighted(a, b, h.alpha, h.beta);
  }
  return sum;
}

double trochoidLoops(const SmoothGuide &guide, double step) {
  return std::max(1.0, std::ceil((guide.length() + 2 * guide.halfWidth()) / step - 1e-9));
}

std::optional<std::vector<Vec2>> trochoidPoints(const SmoothGuide &guide, const TrochoidMotif &motif,
                                                double chordTolerance, double maxPoints) {
  const double w = guide.halfWidth();
  const double travel = guide.length() + 2 * w;
  const double loopCount = trochoidLoops(guide, motif.step);
  if (!(loopCount * 8 + 1 <= maxPoints))
    return std::nullopt;
  const long loops = long(loopCount);
  const double advance = travel / double(loops); // per loop, <= motif.step
  // The chord of an arc of the curve spanning dtheta strays from it by at
  // most |OM''| dtheta^2 / 8, and |OM''| <= R_t + (advance / 2 pi)^2 |G''|
  // with |G''| <= 2 / w.
  const double bound = motif.radius + std::pow(advance / (2 * kPi), 2) * 2 / w;
  const double dtheta = std::sqrt(8 * chordTolerance / bound);
  const double perLoopCount = std::max(8.0, std::ceil(2 * kPi / dtheta));
  if (!(loopCount * perLoopCount + 1 <= maxPoints))
    return std::nullopt;
  const long perLoop = long(perLoopCount);
  const double sense = motif.ccw ? 1 : -1;
  std::vector<Vec2> out;
  out.reserve(size_t(loops * perLoop + 1));
  for (long k = 0; k <= loops * perLoop; ++k) {
    const double turns = double(k) / double(perLoop);
    const double theta = 2 * kPi * turns;
    out.push_back(guide.at(-w + advance * turns) + motif.radius * Vec2(std::cos(theta), sense * std::sin(theta)));
  }
  return out;
}

double trochoidEngagement(double toolRadius, double loopRadius, double step, double halfWidth) {
  // The trochoid as trochoidPoints makes it along a straight guide: out of
  // the hole the entry bores about the guide's start (radius R_t + R), the
  // guide speeding up from rest, then in steady state. One-degree steps;
  // two loops back cover everything the tool meets.
  constexpr int kPerLoop = 360, kLoops = 5;
  constexpr int kBack = 2 * kPerLoop;
  const SmoothGuide guide({Seg::line({0, 0}, {step * (kLoops + 2), 0})}, halfWidth);
  std::vector<Vec2> path(size_t(kLoops * kPerLoop));
  for (size_t i = 0; i < path.size(); ++i) {
    const double turns = double(i) / kPerLoop, theta = 2 * kPi * turns;
    path[i] = guide.at(-halfWidth + step * turns) + loopRadius * Vec2(std::cos(theta), std::sin(theta));
  }
  const double bore = loopRadius + toolRadius;
  double largest = 0;
  std::vector<std::pair<double, double>> covered;
  // The arc of the tool circle about `at` within the disc of radius `r` about `c`.
  auto cover = [&](const Vec2 &at, const Vec2 &c, double r) {
    const Vec2 d = c - at;
    const double dist = d.norm();
    if (dist >= r + toolRadius)
      return;
    if (dist + toolRadius <= r) { // the whole circle
      covered.emplace_back(0, 2 * kPi);
      return;
    }
    // Points at angle phi from d: |R u - d|^2 <= r^2, cos(phi) >= (R^2 + dist^2 - r^2) / (2 R dist).
    const double half =
        std::acos(std::clamp((toolRadius * toolRadius + dist * dist - r * r) / (2 * toolRadius * dist), -1.0, 1.0));
    double from = std::atan2(d.y(), d.x()) - half;
    from -= 2 * kPi * std::floor(from / (2 * kPi));
    const double to = from + 2 * half;
    if (to > 2 * kPi) {
      covered.emplace_back(from, 2 * kPi);
      covered.emplace_back(0, to - 2 * kPi);
    } else {
      covered.emplace_back(from, to);
    }
  };
  for (int i = 1; i < kLoops * kPerLoop; ++i) {
    covered.clear();
    const Vec2 &at = path[size_t(i)];
    cover(at, Vec2(0, 0), bore);
    for (int j = std::max(0, i - kBack); j < i; ++j)
      cover(at, path[size_t(j)], toolRadius);
    std::sort(covered.begin(), covered.end());
    double free = 0, reach = 0;
    for (const auto &[from, to] : covered) {
      if (from > reach)
        free += from - reach;
      reach = std::max(reach, to);
    }
    free += std::max(0.0, 2 * kPi - reach);
    largest = std::max(largest, free);
  }
  return largest;
}

double largestTrochoidStep(double toolRadius, double loopRadius, double maxAngle, double upTo) {
  auto engagement = [&](double step) {
    return trochoidEngagement(toolRadius, loopRadius, step, trochoidSmoothing(step, loopRadius));
  };
  if (engagement(upTo) <= maxAngle)
    return upTo;
  // Engagement grows with the step: bisect to a micrometre, keeping the side that holds.
  double lo = 0, hi = upTo;
  while (hi - lo > 1e-3) {
    const double mid = (lo + hi) / 2;
    (engagement(mid) <= maxAngle ? lo : hi) = mid;
  }
  return lo;
}

std::optional<std::vector<Vec2>> plungeCentres(const std::vector<Seg> &chain, double spacing, double reach,
                                               double maxPoints) {
  std::vector<Vec2> out;
  if (chain.empty())
    return out;
  const bool closed = (chain.front().a - chain.back().b).norm() < 1e-7;
  // The weighted length at the start of each segment, the corner before it
  // counted; a point inside a segment is placed in proportion along it.
  std::vector<double> before, weight;
  double total = 0;
  for (size_t i = 0; i < chain.size(); ++i) {
    const Seg &s = chain[i];
    if (i > 0 || closed) {
      const Vec2 u = chain[(i + chain.size() - 1) % chain.size()].tangent(1), v = s.tangent(0);
      total += reach * std::abs(std::atan2(geom::cross(u, v), u.dot(v)));
    }
    before.push_back(total);
    weight.push_back(s.isArc() ? s.length() + reach * std::abs(s.sweep()) : s.length());
    total += weight.back();
  }
  if (closed) { // the corner back into the start is reached at the end
    const Vec2 u = chain.back().tangent(1), v = chain.front().tangent(0);
    total += reach * std::abs(std::atan2(geom::cross(u, v), u.dot(v)));
  }
  const double intervalCount = std::max(1.0, std::ceil(total / spacing - 1e-9));
  if (!(intervalCount + 1 <= maxPoints))
    return std::nullopt;
  const long intervals = long(intervalCount);
  const long count = closed ? intervals : intervals + 1;
  size_t i = 0;
  for (long k = 0; k < count; ++k) {
    const double at = total * double(k) / double(intervals);
    while (i + 1 < chain.size() && before[i + 1] <= at)
      ++i;
    // Inside a corner's share the place is the corner itself.
    const double t = weight[i] > 0 ? std::clamp((at - before[i]) / weight[i], 0.0, 1.0) : 0.0;
    out.push_back(chain[i].at(t));
  }
  return out;
}

} // namespace stepnc::passes
