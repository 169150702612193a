#include "daemon/regions_mover.hpp"

#include <utility>

#include "core/error.hpp"

namespace hapticsim {

void RegionsMover::Ask(const Request& request, std::int64_t now_ns) {
  asked_ = request;
  asked_ns_ = now_ns;
  behind_ = false;
  ready_.reset();
  refusal_.clear();
  if (const auto known = verdicts_.find(KeyOf(request)); known != verdicts_.end()) {
    ready_ = Outcome{Outcome::Kind::kMoveVerified, request, known->second, 0};
    return;
  }
  if (!request.applies_pending) {
    // A node the tool cannot touch is refused before anything moves (cheap: no estimate).
    try {
      ValidateScene(SceneWith(scene_, request.configuration, request.node));
    } catch (const Error& e) {
      refusal_ = e.what();
      return;
    }
  }
  verifier_.Submit([scene = scene_, request] {
    return VerifyCentredOn(scene, request.configuration, request.node);
  });
  if (request.applies_pending) return;  // out of contact: nobody waits, so verify first
  behind_ = true;
  ready_ = Outcome{Outcome::Kind::kMoveUnverified, request,
                   CentredConfiguration{request.configuration, -1, false}, 0};
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
  if (!verdict->result) {
    refused_.insert(KeyOf(request));
    throw Error(verdict->error);
  }
  verdicts_[KeyOf(request)] = *verdict->result;
  Outcome out{Outcome::Kind::kMoveVerified, request, *verdict->result, (now_ns - asked_ns_) * 1e-6};
  if (behind) out.kind = out.centred.fell_back ? Outcome::Kind::kDemote : Outcome::Kind::kConfirmed;
  return out;
}

}  // namespace hapticsim
