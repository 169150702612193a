#include "daemon/regions_mover.hpp"

#include <sstream>
#include <utility>

#include "core/error.hpp"
#include "core/regions/region_partition.hpp"

namespace hapticsim {
std::string RegionsMover::Outcome::Describe() const {
  std::ostringstream text;
  text.precision(3);
  text << std::fixed;
  const double elapsed_s = elapsed_ms * 1e-3;
  if (runaway) {
    text << "the state of " << DescribeConfiguration(request.configuration) << " around "
         << DescribeContactNode(request.node)
         << " outgrew what the energy balance allows (runaway watch: " << std::scientific
         << runaway_energies.state_j << " J against " << runaway_energies.allowed_j
         << " J allowed); " << std::fixed
         << (to.centred.configuration == request.configuration
                 ? "already at equal rates: restarting them from rest"
                 : "secondaries at the primary rate there, from rest");
    return text.str();
  }
  switch (kind) {
    case Kind::kMoveUnverified:
    case Kind::kMoveVerified:
      text << "regions centred on " << DescribeContactNode(to.node) << " " << elapsed_s
           << " s after it was asked for";
      if (kind == Kind::kMoveUnverified) {
        text << "; they are being checked behind them";
      } else if (to.centred.fell_back) {
        text << "; the chosen configuration ran away around it before: secondaries at the "
                "primary rate there";
      }
      break;
    case Kind::kConfirmed:
    case Kind::kDemote:  // only ever the runaway watch's, described above (runaway is set)
      text << DescribeConfiguration(request.configuration) << " around "
           << DescribeContactNode(request.node) << " checked " << elapsed_s
           << " s after the touch asked for the regions there: it runs there";
      break;
    case Kind::kMoveBack:
      text << why_not << "; the regions go back to " << DescribeContactNode(to.node) << " ("
           << DescribeConfiguration(to.centred.configuration) << ")";
      break;
  }
  return text.str();
}

RegionsMover::RegionsMover(const Scene& scene, const Placement& at, Verifier verify)
    : scene_(scene), placed_(at), last_verified_(at), verify_(std::move(verify)) {
  if (at.centred.verified) {  // the start is verified: a touch back there need not be
    verdicts_[KeyOf({at.centred.configuration, at.node})] = at.centred;
  }
}

void RegionsMover::Ask(const Request& request, std::int64_t now_ns) {
  asked_ = request;
  asked_ns_ = now_ns;
  behind_ = false;
  ready_.reset();
  refusal_.clear();
  if (const auto known = verdicts_.find(KeyOf(request)); known != verdicts_.end()) {
    ready_ = Outcome{Outcome::Kind::kMoveVerified, request, {known->second, request.node}, 0, ""};
    return;
  }
  if (request.touch_waits) {
    // A node the tool cannot touch, or regions that cannot be built around it, are refused
    // before anything moves (cheap: no estimate, no operators).
    try {
      const Scene centred = SceneWith(scene_, request.configuration, request.node);
      ValidateScene(centred);
      (void)RegionPartition(centred);
    } catch (const Error& e) {
      refusal_ = e.what();
      return;
    }
  }
  verifier_.Submit([scene = scene_, request, verify = verify_] {
    return verify(scene, request.configuration, request.node);
  });
  if (!request.touch_waits) return;  // nobody waits, so verify first
  behind_ = true;
  ready_ = Outcome{Outcome::Kind::kMoveUnverified,
                   request,
                   {CentredConfiguration{request.configuration, false, false}, request.node},
                   0,
                   ""};
}

std::optional<RegionsMover::Outcome> RegionsMover::Poll(std::int64_t now_ns) {
  if (!asked_) return std::nullopt;
  if (!refusal_.empty()) {
    refused_.insert(KeyOf(*asked_));
    asked_.reset();
    throw Error(std::exchange(refusal_, std::string()));
  }
  if (ready_) {
    Outcome out = std::move(*ready_);
    ready_.reset();
    out.elapsed_ms = (now_ns - asked_ns_) * 1e-6;
    if (!behind_) asked_.reset();  // a move made unverified stays asked until its verdict
    return out;
  }
  return TakeVerdict(now_ns);
}

std::optional<RegionsMover::Outcome> RegionsMover::TakeVerdict(std::int64_t now_ns) {
  std::optional<BackgroundWorker<CentredConfiguration>::Outcome> verdict = verifier_.Take();
  if (!verdict) return std::nullopt;
  const Request request = *asked_;
  const bool behind = behind_;
  asked_.reset();
  behind_ = false;
  const double elapsed_ms = (now_ns - asked_ns_) * 1e-6;
  if (!verdict->result) {
    refused_.insert(KeyOf(request));
    if (!behind) throw Error(verdict->error);
    return Outcome{Outcome::Kind::kMoveBack, request, last_verified_, elapsed_ms, verdict->error};
  }
  verdicts_[KeyOf(request)] = *verdict->result;
  Outcome out{
      Outcome::Kind::kMoveVerified, request, {*verdict->result, request.node}, elapsed_ms, ""};
  if (behind) out.kind = Outcome::Kind::kConfirmed;
  return out;
}

void RegionsMover::OnRunaway(std::int64_t now_ns, const RunawayEnergies& measured) {
  const Request ran{placed_.centred.configuration, placed_.node};
  refusal_.clear();
  const CentredConfiguration equal{AtEqualRates(scene_, ran.configuration), true, true};
  // From now on, a touch there asking for this configuration moves straight to equal rates.
  verdicts_[KeyOf(ran)] = equal;
  // Whatever was asked is given up (a verification running is dropped by the next Submit):
  // the regions leave this configuration at the next Poll.
  asked_ = ran;
  asked_ns_ = now_ns;
  behind_ = false;
  ready_ = Outcome{Outcome::Kind::kDemote, ran, {equal, ran.node}, 0, ""};
  ready_->runaway = true;
  ready_->runaway_energies = measured;
}

void RegionsMover::Applied(const Outcome& outcome) {
  placed_ = outcome.to;
  if (outcome.kind != Outcome::Kind::kMoveUnverified) last_verified_ = outcome.to;
}

void RegionsMover::NotApplied(const Outcome& outcome) {
  using Kind = Outcome::Kind;
  if (outcome.kind == Kind::kDemote || outcome.kind == Kind::kMoveBack) {
    asked_ = outcome.request;  // the regions still run it: asked again at the next Poll
    ready_ = outcome;
    behind_ = false;
  } else if (outcome.kind == Kind::kMoveUnverified) {
    asked_.reset();  // never moved: its verdict (dropped by the next Submit) is not wanted
    behind_ = false;
  }
}

}  // namespace hapticsim
