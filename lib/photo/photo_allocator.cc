#include "lib/photo/photo_allocator.h"

#include <sys/mman.h>

#include <algorithm>
#include <cstdlib>
#include <deque>
#include <mutex>
#include <new>
#include <utility>

namespace lumislab {
namespace {

// cv::Mat's standard allocator (OpenCV's StdMatAllocator), except that a buffer of 4 MB or more
// is aligned to 2 MB, marked for transparent huge pages, and kept when released for the next
// image of the same byte size. (Fresh pages are zeroed by the kernel at first touch: with 864 MB
// of JPEG photo buffers per 6000 x 4000 position, a large part of its CPU time; the photos of the
// next position have the same sizes.) The kept buffers and those in use add up to at most the
// most bytes ever in use at once (the oldest kept buffers are freed first), so the process never
// holds more than at its busiest. Other buffers are freed with std::free.
class HugePageAllocator : public cv::MatAllocator {
 public:
  cv::UMatData* allocate(int dims, const int* sizes, int type, void* data0, size_t* step,
                         cv::AccessFlag, cv::UMatUsageFlags) const override {
    size_t total = CV_ELEM_SIZE(type);
    for (int i = dims - 1; i >= 0; --i) {
      if (step) {
        if (data0 && step[i] != cv::Mat::AUTO_STEP) {
          CV_Assert(total <= step[i]);
          total = step[i];
        } else {
          step[i] = total;
        }
      }
      total *= size_t(sizes[i]);
    }
    void* data = data0;
    if (!data) data = Huge(total) ? TakeKept(total) : nullptr;
    if (!data) {
      if (posix_memalign(&data, Huge(total) ? kHuge : 64, std::max<size_t>(total, 1)) != 0) {
        if (Huge(total)) Uncount(total);
        throw std::bad_alloc();
      }
#ifdef MADV_HUGEPAGE
      // Advice only: where the kernel has no THP the pages stay 4 kB.
      if (Huge(total)) madvise(data, total / kHuge * kHuge, MADV_HUGEPAGE);
#endif
    }
    auto* u = new cv::UMatData(this);
    u->data = u->origdata = static_cast<uchar*>(data);
    u->size = total;
    if (data0) u->flags |= cv::UMatData::USER_ALLOCATED;
    return u;
  }
  bool allocate(cv::UMatData* u, cv::AccessFlag, cv::UMatUsageFlags) const override {
    return u != nullptr;
  }
  void deallocate(cv::UMatData* u) const override {
    if (!u) return;
    CV_Assert(u->urefcount == 0 && u->refcount == 0);
    if (!(u->flags & cv::UMatData::USER_ALLOCATED)) {
      if (Huge(u->size))
        Keep(u->origdata, u->size);
      else
        std::free(u->origdata);
    }
    delete u;
  }

 private:
  static constexpr size_t kHuge = size_t(2) << 20;
  static bool Huge(size_t bytes) { return bytes >= 2 * kHuge; }

  // A kept buffer of exactly `bytes` (the most recently kept), or nullptr: the caller allocates
  // a fresh one, counted here as in use.
  void* TakeKept(size_t bytes) const {
    std::lock_guard<std::mutex> lock(mutex_);
    in_use_ += bytes;
    for (auto k = kept_.rbegin(); k != kept_.rend(); ++k)
      if (k->second == bytes) {
        void* data = k->first;
        kept_bytes_ -= bytes;
        kept_.erase(std::next(k).base());
        return data;
      }
    peak_ = std::max(peak_, in_use_);
    FreeOldestKept();
    return nullptr;
  }
  void Uncount(size_t bytes) const {  // a fresh buffer that could not be allocated
    std::lock_guard<std::mutex> lock(mutex_);
    in_use_ -= bytes;
  }
  void Keep(void* data, size_t bytes) const {
    std::lock_guard<std::mutex> lock(mutex_);
    in_use_ -= bytes;
    kept_.emplace_back(data, bytes);
    kept_bytes_ += bytes;
    FreeOldestKept();
  }
  // Frees the oldest kept buffers until kept + in use <= peak (mutex_ held).
  void FreeOldestKept() const {
    while (!kept_.empty() && kept_bytes_ + in_use_ > peak_) {
      std::free(kept_.front().first);
      kept_bytes_ -= kept_.front().second;
      kept_.pop_front();
    }
  }

  mutable std::mutex mutex_;
  mutable std::deque<std::pair<void*, size_t>> kept_;  // oldest first
  mutable size_t kept_bytes_ = 0, in_use_ = 0, peak_ = 0;
};

// The allocator of NewPhotoImage. Never destroyed: images held by other static objects may
// outlive any static allocator.
cv::MatAllocator* PhotoAllocator() {
  static HugePageAllocator* const allocator = new HugePageAllocator;
  return allocator;
}

}  // namespace

cv::Mat NewPhotoImage(int rows, int cols, int type) {
  cv::Mat image;
  image.allocator = PhotoAllocator();
  image.create(rows, cols, type);
  // Later create() calls on this Mat (or its copies) would keep the allocator: only the
  // buffer is ours.
  image.allocator = nullptr;
  return image;
}

}  // namespace lumislab
