// Progressive resolution for one view (issue 31): after an edit the view first renders at 1/F of its resolution in
// each axis, F chosen from the measured cost of its earlier renders so that the first image arrives within the budget
// (~33 ms), then at F/2, F/4, ... up to full resolution, where a progressive technique goes on accumulating. A new edit
// starts the sequence again. Interactive renderers do the same (Cycles' viewport, Arnold's IPR).
//
// Pure: the clock is injected, so that tests drive it with simulated timings. The cost model is
//   seconds(F) = fixed + full / F^2,
// fitted to the last render at each factor: `full` is the part that scales with the pixels, `fixed` what does not (a
// BVH rebuild, ISV's sort and shadow-map slabs, a dispatch). With measurements at two factors both follow; with one,
// all of it is taken to scale with the pixels (the optimistic guess, corrected by the next measurement).
#pragma once

#include <array>
#include <functional>
#include <optional>

namespace tyndall::studio {

class ResolutionSchedule {
public:
    static constexpr std::array<int, 5> kFactors = {1, 2, 4, 8, 16};
    static constexpr double kDefaultBudgetSeconds = 0.033;

    explicit ResolutionSchedule(std::function<double()> clock, double budgetSeconds = kDefaultBudgetSeconds);

    // An edit: the sequence starts again. Returns the first factor: the smallest whose predicted time fits the budget,
    // the largest when none does, 1 before anything was measured or when full resolution fits.
    int begin();
    // The render at `factor` of the current sequence delivered its (first) image now: its cost is recorded, and the
    // factor to render next is returned (factor / 2), or 1 after the last reduced one, or 0 once full resolution has
    // delivered (the sequence is done; a progressive technique goes on accumulating). A stage that is not the current
    // one (an image of an older sequence) changes nothing and returns 0.
    // `renderSeconds`, when known (>= 0), is the render's own time, without its wait in the queue: the cost recorded
    // instead of the time since the stage began.
    int delivered(int factor, double renderSeconds = -1.0);
    int current() const { return current_; }  // the stage rendering now (0: none)
    // A stage of the current sequence has delivered its image: what renders now only refines what is on screen (a
    // newer edit need not wait for it).
    bool shown() const { return shown_; }

    // The predicted seconds to the first image at `factor` (nullopt before any measurement).
    std::optional<double> predicted(int factor) const;
    double budget() const { return budget_; }

private:
    static int indexOf(int factor);

    std::function<double()> clock_;
    double budget_;
    std::array<std::optional<double>, kFactors.size()> measured_{};  // the last render's seconds at each factor
    int current_ = 0;
    double started_ = 0.0;  // when the current stage started
    double spent_ = 0.0;    // seconds of the current sequence's reduced stages
    bool shown_ = false;    // a stage of the current sequence delivered
};

}  // namespace tyndall::studio
