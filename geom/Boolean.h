// Exact Boolean operations on regions bounded by lines and arcs: the only
// interface to CGAL in stepnc (Boolean.cpp is the only file that includes it;
// CGAL is slow to compile and nothing else needs to see it).
//
// Each line becomes a CGAL segment between its two end points (doubles are
// rationals, so adjacent segments share end points exactly) and each arc the
// circle through its end points and its mid point, so arcs stay arcs. CGAL
// computes the result exactly; it comes back as doubles (a few ulps of
// rounding in the coordinates of computed intersection points).
#pragma once

#include "geom/Geometry.h"

#include <vector>

namespace stepnc::geom {

Region unite(const Region &a, const Region &b);
Region subtract(const Region &a, const Region &b);
Region intersect(const Region &a, const Region &b);
/// The union of many regions at once (much faster than uniting them one by one).
Region uniteAll(const std::vector<Region> &parts);

/// The area a disc of radius r sweeps when its centre runs along the segments:
/// the union of a capsule per line and an annular sector plus two end discs
/// per arc. The segments need not be connected.
Region sweptDisc(const std::vector<Seg> &centrePath, double r);

/// The pieces a disc of radius r sweeps along one segment, before their union.
std::vector<Region> sweptDiscParts(const Seg &s, double r);

/// Morphological offsets computed with Booleans: region minus the disc swept
/// along its own boundary (shrink) or plus it (grow). Slower than geom::offset
/// but made from separate code, which is what the toolpath verifier needs.
Region shrinkExact(const Region &r, double d);
Region growExact(const Region &r, double d);

} // namespace stepnc::geom
