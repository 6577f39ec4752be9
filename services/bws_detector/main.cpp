/// @file
/// bws_detector process: P1 of the right-most book from STEREO_IMAGES + MARKERS -> BOOK_CORNER_STEREO.
#if __has_include(<malloc.h>)
#include <malloc.h>
#endif

#include "services/bws_detector/bws_detector_service.h"

int main(int argc, char** argv) {
#if defined(__GLIBC__) && defined(M_MMAP_THRESHOLD)
  // Every frame allocates and frees the same few megabytes (disparity, points, labels, decoded images).
  // By default glibc serves big blocks with mmap and trims the heap's top after a free, so each frame
  // faulted in ~2,000 fresh pages (~6 us each). Keep them in the heap and the heap untrimmed: the
  // process stays at its peak frame footprint and reuses it.
  mallopt(M_MMAP_THRESHOLD, 64 << 20);
  mallopt(M_TRIM_THRESHOLD, 512 << 20);
#endif
  return bookgrasp::run_service_main(argc, argv, bookgrasp::bws_detector_service());
}
