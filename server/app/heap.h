/* The service's heap settings. An edit of a large model allocates and frees meshes, trees and
 * texts of megabytes each time; by default glibc hands such blocks straight back to the kernel
 * (mmap'd, or trimmed off the heap's top) and the next edit faults every page in again: at
 * 200k triangles that was a third of an edit's time. ag_heap_keep_large_blocks keeps them in
 * the heap for reuse (blocks up to 64 MiB come from the heap; up to 256 MiB of free space at
 * its top stays mapped). Process-wide; archgramd and the benchmarks that measure what it does
 * call it once at start-up. */
#ifndef AG_HEAP_H
#define AG_HEAP_H

void ag_heap_keep_large_blocks(void);

#endif
