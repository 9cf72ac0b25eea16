#pragma once
/// \file thread_pool.hpp
/// A fixed pool of worker threads created once (filters build it at construction, never per step).
/// parallel_for(n, fn) splits [0, n) into one contiguous chunk per thread; the calling thread runs chunk 0,
/// so a pool of size 1 has no worker and no synchronisation cost.
///
/// Hand-off: a filter step calls parallel_for a few times with short serial parts in between, so a
/// condition-variable wake-up (tens of microseconds) would eat the gain of a second core. Workers and
/// the caller therefore poll atomics for a short while (kSpin polls: pause hints, then yields) before
/// blocking on the condition variables; an idle pool still sleeps. The mutex and the condition variables
/// are touched only when a thread is asleep: an empty 2-thread parallel_for takes about 0.62 us on a 2-vCPU
/// KVM machine, against 0.84 us when every hand-off locked the mutex (BM_PoolParallelFor; a SpinBarrier
/// round, BM_SpinBarrier, about 0.23 us).
#include <atomic>
#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "nlosloc/core/ensure.hpp"

namespace nlosloc::rbpf {

namespace detail {
/// One poll of a spin: a pause hint for the first polls, then yield (so an oversubscribed machine runs the
/// thread being waited for instead of the spinner).
inline void spin_relax(int i) {
#if defined(__x86_64__) || defined(__i386__)
  if (i < 128) {
    __builtin_ia32_pause();
    return;
  }
#endif
  (void)i;
  std::this_thread::yield();
}
}  // namespace detail

/// Barrier for the threads of one parallel_for(n) region with n <= size(), where each thread runs exactly
/// one index and all of them run at once: a step can then keep one region across a short serial part
/// instead of ending it and starting another. Spins (detail::spin_relax); reusable (generation count).
/// Every thread of a region passes the same `threads` (= n).
class SpinBarrier {
 public:
  void arrive_and_wait(int threads) {
    if (threads <= 1) return;  // (no throw here: a thread leaving a region early would strand the others)
    const unsigned g = gen_.load(std::memory_order_acquire);
    if (count_.fetch_add(1, std::memory_order_acq_rel) == threads - 1) {
      count_.store(0, std::memory_order_relaxed);
      gen_.fetch_add(1, std::memory_order_release);
      return;
    }
    for (int i = 0; gen_.load(std::memory_order_acquire) == g; ++i) detail::spin_relax(i);
  }

 private:
  std::atomic<int> count_{0};
  std::atomic<unsigned> gen_{0};
};

/// One-way signal inside a parallel region: one thread writes some data and publishes the region's
/// generation g (release); the others wait for g (acquire) before they read the data. Spins like
/// SpinBarrier; reusable, each region passing a new generation.
class SpinFlag {
 public:
  void publish(unsigned g) { gen_.store(g, std::memory_order_release); }
  void wait(unsigned g) const {
    for (int i = 0; !ready(g); ++i) detail::spin_relax(i);
  }
  /// True once g is published (acquire: the data written before it may then be read); never waits.
  bool ready(unsigned g) const { return gen_.load(std::memory_order_acquire) == g; }

 private:
  alignas(64) std::atomic<unsigned> gen_{0};
};

/// Chunks [0, n) of a parallel region's loop, claimed one at a time at run time: thread 0 takes them from
/// the first on, the others from the last back. The threads then follow the cores' speeds (on a shared
/// host one vCPU may run 20-30% slower than the other for a while), and each keeps to its end step after
/// step, so the data it wrote last step stays in its core's cache. reset() before the region (its
/// hand-off or a barrier publishes it); each thread keeps its own `front` counter, 0 at the start.
class EndClaims {
 public:
  void reset() {
    taken_.store(0, std::memory_order_relaxed);
    back_.store(0, std::memory_order_relaxed);
  }
  /// The next chunk for thread th, or -1 once all n are taken. The claims that succeed number n exactly,
  /// so the front and the back never hand out the same chunk.
  int claim(int th, int n, int& front) {
    if (taken_.fetch_add(1, std::memory_order_relaxed) >= n) return -1;
    return th == 0 ? front++ : n - 1 - back_.fetch_add(1, std::memory_order_relaxed);
  }

 private:
  alignas(64) std::atomic<int> taken_{0};
  std::atomic<int> back_{0};
};

/// Persistent thread pool for the UKF bank and the particle filter.
class ThreadPool {
 public:
  /// `threads` >= 1 (total threads including the caller).
  explicit ThreadPool(int threads = 1) : size_(threads) {
    NLOSLOC_ENSURE(threads >= 1, "threads: expected an integer >= 1, got " + std::to_string(threads));
    for (int w = 1; w < threads; ++w) workers_.emplace_back([this, w] { loop(w); });
  }
  ~ThreadPool() {
    {
      std::lock_guard<std::mutex> lk(m_);
      stop_.store(true, std::memory_order_release);
      gen_.fetch_add(1, std::memory_order_release);
    }
    cv_.notify_all();
    for (auto& t : workers_) t.join();
  }
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  int size() const { return size_; }

  /// Runs fn(begin, end, thread) on size() contiguous chunks of [0, n) and waits; the first exception
  /// thrown by any chunk is rethrown here.
  template <class Fn>
  void parallel_for(int n, Fn&& fn) {
    if (n <= 0) return;
    if (size_ == 1 || n == 1) {
      fn(0, n, 0);
      return;
    }
    std::function<void(int, int, int)> job = [&fn](int b, int e, int t) { fn(b, e, t); };
    job_ = &job;
    n_ = n;
    error_ = nullptr;
    pending_.store(size_ - 1, std::memory_order_relaxed);
    // Dekker pair with a worker going to sleep (loop): it raises sleepers_ and then re-reads gen_, we bump
    // gen_ and then read sleepers_ (both seq_cst), so one of us sees the other.
    gen_.fetch_add(1, std::memory_order_seq_cst);
    if (sleepers_.load(std::memory_order_seq_cst) > 0) {
      std::lock_guard<std::mutex> lk(m_);
      cv_.notify_all();
    }
    std::exception_ptr mine;
    try {
      run_chunk(0);
    } catch (...) {
      mine = std::current_exception();
    }
    for (int i = 0; i < kSpin && pending_.load(std::memory_order_acquire) != 0; ++i) detail::spin_relax(i);
    if (pending_.load(std::memory_order_acquire) != 0) {
      std::unique_lock<std::mutex> lk(m_);
      caller_waits_.store(true, std::memory_order_seq_cst);  // read by the last worker after its decrement
      done_cv_.wait(lk, [this] { return pending_.load(std::memory_order_seq_cst) == 0; });
      caller_waits_.store(false, std::memory_order_relaxed);
    }
    // The workers wrote error_ before their decrement of pending_, which we have read (acquire).
    job_ = nullptr;
    if (mine) std::rethrow_exception(mine);
    if (error_) std::rethrow_exception(error_);
  }

 private:
  static constexpr int kSpin = 2000;
  void run_chunk(int t) {
    const int b = static_cast<int>(static_cast<long long>(n_) * t / size_);
    const int e = static_cast<int>(static_cast<long long>(n_) * (t + 1) / size_);
    if (b < e) (*job_)(b, e, t);
  }
  void loop(int w) {
    unsigned long seen = 0;
    for (;;) {
      unsigned long g = gen_.load(std::memory_order_acquire);
      for (int i = 0; i < kSpin && g == seen; ++i) {
        detail::spin_relax(i);
        g = gen_.load(std::memory_order_acquire);
      }
      if (g == seen) {
        std::unique_lock<std::mutex> lk(m_);
        sleepers_.fetch_add(1, std::memory_order_seq_cst);  // then the predicate re-reads gen_ (seq_cst)
        cv_.wait(lk, [&] { return gen_.load(std::memory_order_seq_cst) != seen; });
        sleepers_.fetch_sub(1, std::memory_order_relaxed);
        g = gen_.load(std::memory_order_acquire);
      }
      seen = g;
      if (stop_.load(std::memory_order_acquire)) return;
      std::exception_ptr err;
      try {
        run_chunk(w);
      } catch (...) {
        err = std::current_exception();
      }
      if (err) {
        std::lock_guard<std::mutex> lk(m_);
        if (!error_) error_ = err;
      }
      // Dekker pair with the caller's blocking wait: wake it only when it may sleep (see parallel_for).
      if (pending_.fetch_sub(1, std::memory_order_seq_cst) == 1 &&
          caller_waits_.load(std::memory_order_seq_cst)) {
        std::lock_guard<std::mutex> lk(m_);  // the caller holds m_ until it is inside wait()
        done_cv_.notify_one();
      }
    }
  }

  int size_;
  std::vector<std::thread> workers_;
  std::mutex m_;
  std::condition_variable cv_, done_cv_;
  std::function<void(int, int, int)>* job_ = nullptr;
  int n_ = 0;
  // Written by the caller each region, polled by the workers: a line of their own, away from the mutex.
  alignas(64) std::atomic<unsigned long> gen_{0};
  std::atomic<int> pending_{0};
  std::atomic<int> sleepers_{0};           // workers blocked (or about to block) on cv_
  std::atomic<bool> caller_waits_{false};  // the caller is blocked (or about to block) on done_cv_
  std::atomic<bool> stop_{false};
  std::exception_ptr error_;
};

}  // namespace nlosloc::rbpf
