#include "core/regions/region_stroke_trial.hpp"

#include <algorithm>
#include <cmath>
#include <memory>

#include "core/error.hpp"
#include "core/regions/async_regions.hpp"
#include "core/regions/proxy_following.hpp"
#include "core/regions/trial_divergence.hpp"
#include "core/scene/contact_trajectory.hpp"
#include "core/trial/proxy_contact.hpp"
#include "core/trial/trial_recorder.hpp"

namespace hapticsim {
namespace {

// Regions on `scene` stepped in `order`.
std::unique_ptr<AsyncRegions> RegionsIn(const Scene& scene, SteppingOrder order) {
  auto regions = std::make_unique<AsyncRegions>(scene);
  regions->SetSteppingOrder(order);
  return regions;
}

// Regions around `centre`, started from `state`.
std::unique_ptr<AsyncRegions> RegionsAround(Scene scene, const LatticeIndex& centre,
                                            const ObjectState& state, SteppingOrder order) {
  scene.input.contact_node = centre;
  auto regions = RegionsIn(scene, order);
  regions->RestoreState(state);
  return regions;
}

// The proxy and the regions must agree on the loads' order: one list, two owners.
void CheckAgree(const ProxyContact& proxy, const AsyncRegions& regions) {
  HAPTICSIM_THROW_UNLESS(proxy.loaded_dofs() == regions.proxy_loaded_dofs(),
                         "internal: the proxy and the primary region load different nodes");
}

// Adds what `regions` spent and balanced to the stroke's totals.
void Accumulate(AsyncRegions& regions, RegionStrokeResult* out) {
  out->compute_s.resize(static_cast<std::size_t>(regions.num_regions()), 0.0);
  for (RegionIndex r = 0; r < regions.num_regions(); ++r)
    out->compute_s[r] += regions.compute_seconds(r);
  const EnergyAccount e = regions.Energies();
  EnergyAccount& sum = out->energy;
  sum.stored_j = e.stored_j;
  sum.input_work_j += e.input_work_j;
  sum.damping_dissipated_j += e.damping_dissipated_j;
  sum.credited_damping_j += e.credited_damping_j;
  sum.interface_created_j += e.interface_created_j;
  sum.interface_dissipated_j += e.interface_dissipated_j;
  sum.port_refused_j += e.port_refused_j;
}

// One stroke in progress: the regions it runs on now, the proxy and the periods' bookkeeping.
class StrokeRun {
 public:
  StrokeRun(const Scene& scene, const TrialFrames& frames,
            const std::function<void(const AsyncRegions&)>& regions_now, SteppingOrder order)
      : scene_(scene),
        frames_(frames),
        regions_now_(regions_now),
        order_(order),
        regions_(RegionsIn(scene, order)),
        normal_(regions_->partition().contact_normal()),
        centre_(regions_->partition().contact_node()),
        proxy_(regions_->partition().PrimaryProxySurface(), centre_, normal_, scene.contact),
        trajectory_(scene.input, normal_),
        dt_(1.0 / regions_->schedule(kPrimaryRegion).rate_hz),
        steps_(std::lround(scene.input.periods / scene.input.frequency_hz / scene.solver.dt_s)),
        recorder_(trajectory_, dt_, steps_, &out_.stroke.trial) {
    const auto stroke_axis = static_cast<std::size_t>(scene.input.stroke_axis);
    HAPTICSIM_THROW_UNLESS(
        normal_[stroke_axis] == 0,
        "input.stroke_direction = " + GetSceneValue(scene, "input.stroke_direction") +
            " points into the contact's face: a stroke moves along the face, "
            "choose one of the other two axes");
    CheckAgree(proxy_, *regions_);
    out_.stroke.trial.stability = regions_->schedule(kPrimaryRegion).alone;
    out_.stroke.proxy.reserve(static_cast<std::size_t>(steps_) + 1);
    budget_j_ = regions_->Energy();
    if (regions_now_) regions_now_(*regions_);
  }

  RegionStrokeResult Run() && {
    for (long n = 0; n <= steps_ && StepPeriod(n) && WithinBudget(); ++n) {
      if (n >= steps_) continue;
      if (const std::optional<LatticeIndex> next = FollowTo()) MoveTo(*next, n);
    }
    out_.stroke.trial.wall_time_s = recorder_.ElapsedS();
    Accumulate(*regions_, &out_);
    return std::move(out_);
  }

 private:
  // Where the primary should follow the proxy to (ProxyWantsPrimaryAt), if anywhere.
  std::optional<LatticeIndex> FollowTo() const {
    return ProxyWantsPrimaryAt(proxy_, centre_, regions_->partition().mesh().options().spacing_m);
  }

  // Period n: the primary stepped once per substep, the proxy touching with the tool where
  // hapticsimd has it (ContactTrajectory::SubstepToolAt) and the spring taken at the step's end
  // (ProxyPush). The period's sample is its first substep's force. False when the trial ends in
  // it.
  bool StepPeriod(long n) {
    if (frames_.Due(n)) frames_.observe(n * dt_, regions_->CaptureState());
    const int substeps = regions_->schedule(kPrimaryRegion).substeps;
    for (int q = 0; q < substeps; ++q) {
      std::array<double, 3> tool = proxy_.start_m();
      const std::array<double, 3> moved = trajectory_.SubstepToolAt(n, q, substeps, dt_);
      for (int c = 0; c < 3; ++c) tool[c] += moved[c];
      regions_->AdvanceSecondariesForPrimaryStep();
      ProxyPush push(proxy_, tool);
      regions_->StepPrimaryPushed(push);
      const ProxyContact::Result& touch = push.touch;
      if (touch.left_surface) {
        recorder_.Stop(TrialOutcome::kLeftSurface);
        return false;
      }
      if (touch.left_region) {
        // At the face's rim the primary stayed: the stroke reached the edge of its face. Inside
        // it the proxy slid farther in a period than any tool moves.
        recorder_.Stop(proxy_.InsideFace(proxy_.NearestNode()) ? TrialOutcome::kDivergedContact
                                                               : TrialOutcome::kLeftSurface);
        return false;
      }
      if (q == 0) {
        if (!recorder_.Record(n, touch.force_on_object_n)) return false;
        out_.stroke.proxy.push_back({proxy_.proxy_rest_m(), touch.in_contact, touch.sliding});
      }
    }
    return true;
  }

  // The divergence checks of every trial (AsyncRegions::RunTrial), on the regions of now: false
  // when the trial ends.
  bool WithinBudget() {
    const AsyncRegions::PublishedBalanceView balance = regions_->PublishedBalance();
    const double work = work_before_j_ + regions_->InputWorkJ();
    if (const auto stop = DivergedAfterPeriod(*regions_, balance, balance.state_energy_j,
                                              budget_j_ + work, &runaway_periods_)) {
      recorder_.Stop(stop->outcome, stop->runaway);
      return false;
    }
    return true;
  }

  // The primary re-centred on `next` at the end of period n: new regions, the motion carried.
  void MoveTo(const LatticeIndex& next, long n) {
    const ObjectState state = regions_->CaptureState();
    Accumulate(*regions_, &out_);
    work_before_j_ += regions_->InputWorkJ();
    regions_ = RegionsAround(scene_, next, state, order_);
    proxy_.Rebind(regions_->partition().PrimaryProxySurface());
    CheckAgree(proxy_, *regions_);
    runaway_periods_ = 0;
    centre_ = next;
    if (regions_now_) regions_now_(*regions_);
    out_.moves.push_back({n, centre_});
    StabilityEstimate& stability = out_.stroke.trial.stability;
    const StabilityEstimate& primary = regions_->schedule(kPrimaryRegion).alone;
    if (primary.critical_dt_s < stability.critical_dt_s) stability = primary;
  }

  const Scene& scene_;
  const TrialFrames& frames_;
  const std::function<void(const AsyncRegions&)>& regions_now_;
  SteppingOrder order_;
  RegionStrokeResult out_;
  std::unique_ptr<AsyncRegions> regions_;
  std::array<double, 3> normal_;
  LatticeIndex centre_;
  ProxyContact proxy_;
  ContactTrajectory trajectory_;
  double dt_;
  long steps_;
  TrialRecorder recorder_;
  double budget_j_ = 0;       // what the state held when the stroke started, J
  double work_before_j_ = 0;  // the contact's work on the regions before them, J
  int runaway_periods_ = 0;
};

}  // namespace

RegionStrokeResult RunRegionStroke(const Scene& scene, const TrialFrames& frames,
                                   const std::function<void(const AsyncRegions&)>& regions_now,
                                   SteppingOrder order) {
  HAPTICSIM_THROW_UNLESS(scene.input.waveform == Waveform::kStroke,
                         "internal: RunRegionStroke runs input.waveform = \"stroke\"");
  return StrokeRun(scene, frames, regions_now, order).Run();
}

}  // namespace hapticsim
