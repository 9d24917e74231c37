// The structured projection search (SearchOptions::strategy = "structured").
//
// Cole's greedy search takes, for each new term, the best single projection;
// on a BRDF that is exactly two textures a(P1 x) + b(P2 x) the best single
// plane mixes one direction of each true plane, and no later term undoes it.
// This search keeps the greedy skeleton but changes what it starts from and
// what it may undo:
//  - seeds read off the data: the Hessians of the residual log BRDF (what the
//    terms so far leave unexplained) are estimated in each parameterization
//    and the plane pair that block-diagonalizes them gives two starts
//    (structure.h); with Cole's guesses (wi, wo planes) and `restarts` seeded
//    random rotations, in each allowed parameterization;
//  - screening: every start is evaluated once and Powell runs from the
//    `keep` best distinct ones (in parallel);
//  - pair move: before term j (j >= 2) is taken, the alternative "replace
//    term j-1 and add term j from the seed pair read off the residual of terms
//    1..j-2" is polished and kept if its schedule error is lower (this is what
//    undoes the mixed plane);
//  - polish: at the end, every term is re-searched with the others held
//    (Jacobi sweeps, in parallel; a move is kept only if the re-solved
//    schedule is lower), polish_sweeps times or until nothing moves;
//  - per-term parameterization (term_param = "either"): each start carries
//    its parameterization, so McCool's p(wi) q(h) p(wo) is inside the space.
// The objective is the greedy search's: the fit schedule's least-squares
// error at the search texture size; the result is refitted at texture_size.
#pragma once

#include "search/term_search.h"

namespace bf {

SearchResult structured_search(const FitData& data, const SearchOptions& opt);

}  // namespace bf
