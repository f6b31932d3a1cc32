// The buffers of photo-sized images: large ones in transparent huge pages, kept for the next
// image of the same size.
#pragma once

#include <opencv2/core.hpp>

namespace lumislab {

// A new image for a photo's pixels (type as cv::Mat::create). Large ones are allocated in
// transparent huge pages (madvise(MADV_HUGEPAGE), for a kernel whose THP mode is `madvise`):
// filling a fresh 144 MB image takes ~37000 first-touch page faults in 4 kB pages against ~72 in
// 2 MB pages. Released as any cv::Mat; a large one's buffer is kept for the next image of its
// size (the kernel zeroes fresh pages, photo_allocator.cc).
cv::Mat NewPhotoImage(int rows, int cols, int type);

}  // namespace lumislab
