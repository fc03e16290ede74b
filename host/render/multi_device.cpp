#include "render/multi_device.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <functional>
#include <thread>

#include "util/check.h"
#include "util/interrupt.h"

namespace pr {

namespace {

// Runs fn(0..n-1) on a thread each (inline for one), then rethrows the lowest index's error.
void forEachDevice(size_t n, const std::function<void(size_t)>& fn) {
  std::vector<std::exception_ptr> errors(n);
  auto run = [&](size_t i) {
    try {
      fn(i);
    } catch (...) {
      errors[i] = std::current_exception();
    }
  };
  if (n == 1) {
    run(0);
  } else {
    std::vector<std::thread> threads;
    threads.reserve(n);
    for (size_t i = 0; i < n; ++i) threads.emplace_back(run, i);
    for (auto& t : threads) t.join();
  }
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);
}

}  // namespace

std::vector<int> splitRows(int height, const std::vector<double>& weights) {
  const size_t n = weights.size();
  PR_CHECK(n > 0 && height >= 0);
  std::vector<double> w(weights);
  double sum = 0.0;
  for (double x : w) sum += x > 0.0 && std::isfinite(x) ? x : 0.0;
  for (double& x : w) x = sum > 0.0 ? (x > 0.0 && std::isfinite(x) ? x / sum : 0.0) : 1.0 / n;
  std::vector<int> rows(n, 0);
  std::vector<std::pair<double, size_t>> remainders;
  int given = 0;
  for (size_t i = 0; i < n; ++i) {
    const double exact = height * w[i];
    rows[i] = std::min(height - given, static_cast<int>(std::floor(exact)));
    given += rows[i];
    remainders.push_back({exact - rows[i], i});
  }
  std::stable_sort(remainders.begin(), remainders.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  for (size_t k = 0; given < height; ++k, ++given) ++rows[remainders[k % n].second];
  if (static_cast<size_t>(height) >= n)
    for (size_t i = 0; i < n; ++i)
      if (rows[i] == 0) {
        --*std::max_element(rows.begin(), rows.end());
        rows[i] = 1;
      }
  return rows;
}

std::vector<int> balancePasses(const std::vector<int>& passes, const std::vector<double>& seconds) {
  PR_CHECK(passes.size() == seconds.size() && !passes.empty());
  std::vector<double> rate(passes.size());
  int spp = 0;
  for (size_t i = 0; i < passes.size(); ++i) {
    if (passes[i] <= 0 || !(seconds[i] > 0.0) || !std::isfinite(seconds[i])) return passes;
    rate[i] = passes[i] / seconds[i];
    spp += passes[i];
  }
  const std::vector<int> next = splitRows(spp, rate);
  const auto slowest = [&](const std::vector<int>& split) {
    double t = 0.0;
    for (size_t i = 0; i < split.size(); ++i) t = std::max(t, split[i] / rate[i]);
    return t;
  };
  // A margin, so that timing noise does not move chains back and forth.
  return slowest(next) < 0.85 * slowest(passes) ? next : passes;
}

MultiDeviceSession::MultiDeviceSession(const Scene& scene,
                                       const std::vector<const DeviceEntry*>& devices,
                                       const RenderOptions& options)
    : devices_(devices), sessions_(devices.size()), throughput_(devices.size(), 0.0) {
  PR_CHECK(!devices.empty());
  if (options.timeLimit > 0.0 && devices.size() > 1)
    throw InputError(
        "--time-limit: renders on one device (several split each frame's passes "
        "or rows by measured speed already)");
  if (options.noiseThreshold > 0.0f && devices.size() > 1)
    throw InputError(
        "--noise-threshold: renders on one device (each pixel's budget is planned from its "
        "neighbours, which several devices would split)");
  forEachDevice(devices.size(), [&](size_t i) {
    sessions_[i] = std::make_unique<RenderSession>(scene, *devices[i], options);
  });
  // The first frame: an even split.
  const std::vector<double> even(devices.size(), 1.0);
  spp_ = options.spp;
  denoise_ = options.denoise;
  if (resolveResample(options).enabled && devices.size() > 1) {
    passes_ = splitRows(spp_, even);
    int begin = 0;
    for (size_t i = 0; i < sessions_.size(); ++i) {
      sessions_[i]->setPasses(begin, begin + passes_[i]);
      begin += passes_[i];
    }
    rows_.assign(devices.size(), height());
    return;
  }
  setRows(splitRows(height(), even));
}

void MultiDeviceSession::setPassSplit(const std::vector<int>& passes) {
  PR_CHECK(!passes_.empty() && passes.size() == passes_.size());
  const auto owner = [](const std::vector<int>& split, int pass) {
    size_t i = 0;
    for (int end = split[0]; pass >= end && i + 1 < split.size();) end += split[++i];
    return i;
  };
  // The chains that change device, read before their device frees them.
  std::vector<std::pair<int, std::string>> moving;
  for (int s = 0; s < std::min(spp_, sessions_[0]->chains()); ++s)
    if (owner(passes_, s) != owner(passes, s))
      moving.emplace_back(s, sessions_[owner(passes_, s)]->chain(s));
  passes_ = passes;
  int begin = 0;
  for (size_t i = 0; i < sessions_.size(); ++i) {
    sessions_[i]->setPasses(begin, begin + passes_[i]);
    begin += passes_[i];
  }
  PR_CHECK(begin == spp_);
  for (const auto& [s, records] : moving) sessions_[owner(passes_, s)]->setChain(s, records);
}

void MultiDeviceSession::renderPasses(int64_t frame, Image* img, std::vector<DeviceFrame>* parts) {
  const size_t n = sessions_.size();
  std::vector<std::vector<float>> sums(n);
  std::vector<DeviceFrame>& p = *parts;
  int begin = 0;
  for (size_t i = 0; i < n; ++i) {
    p[i].rowEnd = height();
    p[i].passBegin = begin;
    p[i].passEnd = begin += passes_[i];
    p[i].share = double(passes_[i]) / spp_;
  }
  forEachDevice(n, [&](size_t i) {
    const auto t0 = std::chrono::steady_clock::now();
    sums[i] = sessions_[i]->renderSums(frame, &p[i].stats);
    p[i].wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  });
  // In device order, so that the frame does not depend on which device finished first.
  std::vector<float>& total = sums[0];
  for (size_t i = 1; i < n; ++i)
    for (size_t k = 0; k < total.size(); ++k) total[k] += sums[i][k];
  Film::mean(total.data(), total.size() / 4, img->rgba.data());
}

void MultiDeviceSession::setRows(const std::vector<int>& rows) {
  rows_ = rows;
  int begin = 0;
  for (size_t i = 0; i < sessions_.size(); ++i) {
    sessions_[i]->setRows(begin, begin + rows[i]);
    begin += rows[i];
  }
  PR_CHECK(begin == height());
}

Image MultiDeviceSession::renderFrame(int64_t frame, FrameStats* total,
                                      std::vector<DeviceFrame>* parts) {
  const size_t n = sessions_.size();
  Image img(width(), height());
  std::vector<DeviceFrame> local(n);
  std::vector<DeviceFrame>& p = parts ? *parts : local;
  p.assign(n, DeviceFrame{});
  for (size_t i = 0; i < n; ++i) {
    p[i].index = devices_[i]->index;
    p[i].name = devices_[i]->name;
  }
  if (!passes_.empty()) {
    renderPasses(frame, &img, &p);
    std::vector<double> seconds(n);
    for (size_t i = 0; i < n; ++i) seconds[i] = p[i].wallSeconds;
    const std::vector<int> next = balancePasses(passes_, seconds);
    if (next != passes_ && !interrupted()) setPassSplit(next);
  } else {
    int begin = 0;
    for (size_t i = 0; i < n; ++i) {
      p[i].rowBegin = begin;
      p[i].rowEnd = begin += rows_[i];
      p[i].passEnd = spp_;
      p[i].share = double(rows_[i]) / height();
    }
    // Each thread writes only its own rows of `img`.
    forEachDevice(n, [&](size_t i) {
      const auto t0 = std::chrono::steady_clock::now();
      sessions_[i]->renderRows(frame, &img, &p[i].stats);
      p[i].wallSeconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    });
  }

  // Each pixel's sample count: every device's, where they split rows or passes.
  if (sessions_[0]->samplesAov() && !interrupted()) {
    ImageChannel c{"samples", std::vector<float>(size_t(img.width) * img.height, 0.0f), true};
    for (const auto& s : sessions_) {
      const std::vector<float>& counts = s->sampleCounts();
      for (size_t k = 0; k < counts.size(); ++k) c.values[k] += counts[k];
    }
    img.channels.push_back(std::move(c));
  }
  // Auxiliary images (and denoising) on the first device, for the whole image whatever the split.
  if (sessions_[0]->hasAovs() && !interrupted()) {
    const auto [aov, denoise] = sessions_[0]->renderAovs(frame, &img);
    p[0].stats.stageSeconds["aov"] += aov;
    // Its kernel is built at the first frame that makes them: timed in that frame's line.
    for (const auto& [k, v] : sessions_[0]->context().takeBuildSeconds())
      p[0].stats.buildSeconds[k] += v;
    if (denoise_) p[0].stats.stageSeconds["denoise"] += denoise;
  }

  if (total) {
    FrameStats& t = *total;
    t.frame = frame;
    t.motionSteps = p[0].stats.motionSteps;  // every device places the scene alike
    // Each pixel's samples: every device's passes where they split them, else one's.
    t.passes = 0;
    for (size_t i = 0; i < n; ++i)
      t.passes =
          passes_.empty() ? std::max(t.passes, p[i].stats.passes) : t.passes + p[i].stats.passes;
    if (n == 1) {
      t.sppMean = p[0].stats.sppMean;
      t.sppMax = p[0].stats.sppMax;
    }
    for (size_t i = 0; i < n; ++i) {
      const FrameStats& s = p[i].stats;
      for (const auto& [k, v] : s.stageSeconds) t.stageSeconds[k] += v;
      for (const auto& [k, v] : s.hostSeconds) t.hostSeconds[k] += v;
      for (const auto& [k, v] : s.buildSeconds) t.buildSeconds[k] += v;
      for (const auto& [k, v] : s.rays) t.rays[k] += v;
      for (const auto& [k, v] : s.counters)
        if (i == 0 || !s.lightPathCounters.count(k)) t.counters[k] += v;
      t.lightPathCounters.insert(s.lightPathCounters.begin(), s.lightPathCounters.end());
      t.deviceBytes += s.deviceBytes;
      for (const auto& [k, v] : s.deviceBuffers) t.deviceBuffers[k] += v;
      t.badSamples += s.badSamples;
    }
  }

  // The next frame's split: rows in proportion to rows per second of each device's part.
  if (n > 1 && passes_.empty()) {
    double known = 0.0;
    int counted = 0;
    for (size_t i = 0; i < n; ++i)
      if (rows_[i] > 0 && p[i].wallSeconds > 0.0) {
        throughput_[i] = rows_[i] / p[i].wallSeconds;
        known += throughput_[i];
        ++counted;
      }
    // A device that has not rendered rows yet is taken to be as fast as the mean.
    for (double& t : throughput_)
      if (!(t > 0.0)) t = counted > 0 ? known / counted : 1.0;
    setRows(splitRows(height(), throughput_));
  }
  return img;
}

}  // namespace pr
