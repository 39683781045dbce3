#include "heap.h"

#include <malloc.h>

void ag_heap_keep_large_blocks(void)
{
    mallopt(M_MMAP_THRESHOLD, 64 << 20);
    mallopt(M_TRIM_THRESHOLD, 256 << 20);
}
