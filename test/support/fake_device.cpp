// Scripted fake device on a pty (see the header).
#include "support/fake_device.h"

#include <algorithm>

#include "support/test_helpers.h"

namespace test_support {

namespace protocol = serial_robot_driver::protocol;
namespace sim = serial_robot_driver::sim;

FakeDevice::FakeDevice(std::string link_path, protocol::FramerConfig framer, bool echo)
    : link_path_(std::move(link_path)), framer_config_(framer), echo_(echo) {}

FakeDevice::~FakeDevice() { unplug(); }

void FakeDevice::plug() {
  unplug();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    frames_.clear();
    received_.clear();
    taken_ = 0;
    last_session_stats_ = protocol::FramerStats{};
  }
  pty_ = std::make_unique<sim::PseudoTerminal>(link_path_);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    plugged_at_ = Clock::now();  // once the link exists: what the node sees from now on is new
  }
  reader_ = std::make_unique<PtyFrameReader>(
      *pty_, framer_config_,
      [this](protocol::FrameFamily family, const uint8_t* data, std::size_t size,
             Clock::time_point arrival) { onFrame(family, data, size, arrival); },
      [this](const uint8_t* data, std::size_t size) {
        std::lock_guard<std::mutex> lock(mutex_);
        received_.insert(received_.end(), data, data + size);
      });
}

void FakeDevice::unplug() {
  if (reader_) {
    const protocol::FramerStats stats = reader_->framerStats();
    reader_.reset();
    std::lock_guard<std::mutex> lock(mutex_);
    last_session_stats_ = stats;
  }
  if (pty_) pty_->close();
  pty_.reset();
}

void FakeDevice::answer(const Bytes& request, std::vector<Bytes> replies) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (Rule& rule : rules_) {
    if (!rule.exact.empty() && rule.exact == request) {
      rule.replies = std::move(replies);
      return;
    }
  }
  rules_.push_back(Rule{request, nullptr, std::move(replies), 0});
}

void FakeDevice::answerWhen(Match match, std::vector<Bytes> replies) {
  std::lock_guard<std::mutex> lock(mutex_);
  rules_.push_back(Rule{{}, std::move(match), std::move(replies), 0});
}

std::size_t FakeDevice::hits(const Bytes& request) const {
  std::lock_guard<std::mutex> lock(mutex_);
  for (const Rule& rule : rules_) {
    if (rule.exact == request) return rule.hits;
  }
  return 0;
}

void FakeDevice::write(const Bytes& bytes) { pty_->write(bytes.data(), bytes.size()); }

void FakeDevice::onFrame(protocol::FrameFamily family, const uint8_t* data, std::size_t size,
                         Clock::time_point arrival) {
  Frame frame{family, Bytes(data, data + size), arrival};
  Bytes out;
  if (echo_) out = frame.bytes;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    // Exact rules first, then the predicates in the order they were given.
    auto rule = std::find_if(rules_.begin(), rules_.end(), [&](const Rule& candidate) {
      return !candidate.exact.empty() && candidate.exact == frame.bytes;
    });
    if (rule == rules_.end()) {
      rule = std::find_if(rules_.begin(), rules_.end(), [&](const Rule& candidate) {
        return candidate.exact.empty() && candidate.match(frame);
      });
    }
    if (rule != rules_.end()) {
      ++rule->hits;
      for (const Bytes& reply : rule->replies) out.insert(out.end(), reply.begin(), reply.end());
    }
    frames_.push_back(std::move(frame));
  }
  if (!out.empty()) pty_->write(out.data(), out.size());
}

std::vector<FakeDevice::Frame> FakeDevice::frames() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return frames_;
}

std::size_t FakeDevice::frameCount() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return frames_.size();
}

bool FakeDevice::waitForFrames(const std::function<bool(const std::vector<Frame>&)>& done,
                               double timeout_s) const {
  return waitFor([&] { return done(frames()); }, timeout_s);
}

std::size_t FakeDevice::mark() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return received_.size();
}

FakeDevice::Bytes FakeDevice::bytesSince(std::size_t mark) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return Bytes(received_.begin() + static_cast<std::ptrdiff_t>(std::min(mark, received_.size())),
               received_.end());
}

FakeDevice::Bytes FakeDevice::takeBytes(std::size_t count, double timeout_s) {
  waitFor(
      [&] {
        std::lock_guard<std::mutex> lock(mutex_);
        return received_.size() - taken_ >= count;
      },
      timeout_s);
  std::lock_guard<std::mutex> lock(mutex_);
  const std::size_t available = std::min(count, received_.size() - taken_);
  const auto begin = received_.begin() + static_cast<std::ptrdiff_t>(taken_);
  Bytes bytes(begin, begin + static_cast<std::ptrdiff_t>(available));
  taken_ += available;
  return bytes;
}

void FakeDevice::skipReceived() {
  std::lock_guard<std::mutex> lock(mutex_);
  taken_ = received_.size();
}

protocol::FramerStats FakeDevice::framerStats() const {
  if (reader_) return reader_->framerStats();
  std::lock_guard<std::mutex> lock(mutex_);
  return last_session_stats_;
}

FakeDevice::Clock::time_point FakeDevice::pluggedAt() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return plugged_at_;
}

}  // namespace test_support
