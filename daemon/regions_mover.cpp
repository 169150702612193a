#include "daemon/regions_mover.hpp"

#include "core/error.hpp"

namespace hapticsim {

void RegionsMover::Ask(const Request& request, std::int64_t now_ns) {
  asked_ = request;
  asked_ns_ = now_ns;
  if (const auto known = verdicts_.find(KeyOf(request)); known != verdicts_.end()) {
    known_ = known->second;
    return;
  }
  verifier_.Submit([scene = scene_, request] {
    return VerifyCentredOn(scene, request.configuration, request.node);
  });
}

std::optional<RegionsMover::Verified> RegionsMover::Poll(std::int64_t now_ns) {
  if (!asked_) return std::nullopt;
  std::optional<CentredConfiguration> verdict = std::move(known_);
  known_.reset();
  if (!verdict) {
    std::optional<BackgroundWorker<CentredConfiguration>::Outcome> outcome = verifier_.Take();
    if (!outcome) return std::nullopt;
    const Request request = *asked_;
    if (!outcome->result) {
      refused_.insert(KeyOf(request));
      asked_.reset();
      throw Error(outcome->error);
    }
    verdict = std::move(outcome->result);
    verdicts_[KeyOf(request)] = *verdict;
  }
  Verified done{*asked_, *verdict, (now_ns - asked_ns_) * 1e-6};
  asked_.reset();
  return done;
}

}  // namespace hapticsim
