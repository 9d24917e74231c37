// The structured projection search (SearchOptions::strategy = "structured").
//
// Cole's greedy search takes, for each new term, the best single projection;
// on a BRDF that is exactly two textures a(P1 x) + b(P2 x) the best single
// plane mixes one direction of each true plane, and no later term undoes it.
// This search changes what it starts from and what it keeps:
//  - seeds read off the data: the Hessians of the residual log BRDF (what the
//    terms so far leave unexplained) are estimated in each parameterization
//    and the plane pair that block-diagonalizes them gives two starts
//    (structure.h); with Cole's guesses (wi, wo planes, in each allowed
//    parameterization, so McCool's p(wi) q(h) p(wo) is inside the space) and
//    `restarts` seeded random rotations;
//  - a beam of beam_width partial configurations: at term j every
//    configuration is extended by every start of its own residual, each
//    extension scored by one fit (screening); Powell runs from the `keep`
//    best distinct extensions (in parallel); the next beam holds the best
//    refined configurations (half of it) and then the best unrefined seed or
//    guess configurations. Keeping the unrefined true planes is what undoes
//    the greedy trap: a single plane refined to mix one direction of each
//    true plane fits better alone, but its pair fits worse;
//  - polish: at the end, every term of the best configuration (the lower of
//    the beam's best and the last stage's answer, which may be a side
//    configuration; see below) is re-searched
//    with the others held (Jacobi sweeps, in parallel; a move is kept only if
//    the re-solved objective is lower), polish_sweeps times or until nothing
//    moves; by default only searches of up to kSmallSearchTerms terms (they
//    also keep the wider beam, term_search.h);
//  - joint refit (final_joint): the found projections are refitted with all
//    terms solved together; searches of up to joint_polish_terms terms also
//    polish under that joint objective (the schedule's n = 2 solve cannot
//    reach McCool's error on a BRDF of exactly McCool's form even at the true
//    planes).
//  - re-seeding (searches of 2 to 4 terms, per-term parameterization, with
//    final_joint): under the joint objective, every term and every pair of
//    terms is read again from the residual of the others' jointly fitted
//    textures, in each parameterization separately (alternating seeds and
//    fits, one chain per parameterization, so a replacement that changes the
//    mix is not discarded for a lower one that keeps it); the best
//    replacement, and the best of each other mix of parameterizations within
//    2x (a subset's higher replacement only for a mix no other candidate
//    has), are polished and the lowest kept, rounds until nothing moves. The
//    beam alone missed planes that do not share a parameterization (a halfdiff
//    term perturbs the wiwo Hessians and the reverse). Then each term alone
//    is moved to the other parameterization (Powell from the residual's
//    seeds, the others held). Searches of 2 terms run only these one-term
//    moves (a wiwo and a halfdiff plane: the beam ended at w w or h h) and
//    then random restarts of a wiwo and a halfdiff term together (Powell on
//    both rotations at once), which leave an answer with both planes wrong.
//  - k-term answers: after term k, every configuration of the beam is refit
//    at texture_size and the best is stage k's answer; besides the beam, that
//    answer is extended greedily (its random starts in each parameterization,
//    Powell from the `keep` best screened ones, at least one per
//    parameterization; at the first term from every start of the greedy
//    search with the same seed, restarts and parameterization, so the 1-term
//    answer is never worse than its), and those extensions compete for the
//    next answer.
//    SearchResult::answers[k-1] is the better of stage k's answer and the final
//    answer's k-term prefix (refit jointly), so a 1- or 2-term answer is not
//    bound to the terms chosen for the final count.
// The screening and Powell objective is the greedy search's: the schedule's
// least-squares error at the search texture size (n = solve_last).
#pragma once

#include "search/term_search.h"

namespace bf {

SearchResult structured_search(const FitData& data, const SearchOptions& opt);

// The structured search's revision: raised whenever a change moves its
// answers for the same options. Every non-greedy search run carries it in
// its run id (experiments/methods/search.cpp), so a cached answer of an
// older revision is recomputed instead of reused. 2: 2-term searches run
// the mixed pair's random restarts (2026-11-28). 3: those restarts search
// at half the texture, and also in the answer's mix when its two terms
// share a parameterization (2026-11-29). (final_reciprocity, 2026-11-29,
// did not raise it: its key enters the run id unless it is off, and with it
// off the answers are those of revision 3.)
constexpr int kStructuredSearchRevision = 3;

}  // namespace bf
