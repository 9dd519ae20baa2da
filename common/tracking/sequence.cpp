#include "tracking/sequence.h"

#include <algorithm>

namespace optique::tracking {

bool FrameSequence::goes_on(const Newest& from, const DTrackSample& sample) {
  const double since = static_cast<double>(std::max<Nanos>(0, sample.arrival - from.arrival)) / 1e9;
  if (sample.frame && from.frame) {
    return *sample.frame > *from.frame &&
           static_cast<double>(*sample.frame - *from.frame) <= static_cast<double>(kFramesAhead) + since * kMostFrameRate;
  }
  if (sample.timestamp && from.timestamp) {
    return *sample.timestamp > *from.timestamp && *sample.timestamp - *from.timestamp <= kTimestampAhead + 2.0 * since;
  }
  return true;  // nothing to order by but the arrival (the tracker checks that)
}

Order FrameSequence::order(const DTrackSample& sample) {
  if (!established_ || sample.arrival - established_->arrival > quiet_ || goes_on(*established_, sample)) {
    return Order::next;
  }
  const Newest newest{sample.arrival, sample.frame, sample.timestamp};
  if (candidate_ && candidate_->sender == sample.sender && goes_on(candidate_->newest, sample)) {
    candidate_->newest = newest;
    ++candidate_->datagrams;
  } else {
    candidate_ = Candidate{sample.sender, sample.arrival, newest, 1};
  }
  const bool believed = candidate_->datagrams >= kRestartDatagrams && sample.arrival - candidate_->since >= kRestartSpan;
  return believed ? Order::restart : Order::outside;
}

void FrameSequence::taken(const DTrackSample& sample) {
  established_ = Newest{sample.arrival, sample.frame, sample.timestamp};
  candidate_.reset();
}

}  // namespace optique::tracking
