#include "filemap.h"

#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

ag_status ag_filemap_open(const char *path, ag_filemap *fm, ag_error *err)
{
    memset(fm, 0, sizeof *fm);
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        return ag_error_set(err, AG_ERR_IO, 0, "cannot open %s: %s", path, strerror(errno));
    struct stat sb;
    if (fstat(fd, &sb) != 0 || !S_ISREG(sb.st_mode)) {
        close(fd);
        return ag_error_set(err, AG_ERR_IO, 0, "%s: not a regular file", path);
    }
    fm->len = (size_t)sb.st_size;
    fm->data = (const uint8_t *)"";
    if (fm->len == 0) {
        close(fd);
        return AG_OK;
    }
    void *map = mmap(NULL, fm->len, PROT_READ, MAP_PRIVATE, fd, 0);
    if (map != MAP_FAILED) {
        close(fd);
        madvise(map, fm->len, MADV_SEQUENTIAL);
        fm->map = map;
        fm->data = map;
        return AG_OK;
    }
    /* some file systems cannot map: read it all */
    uint8_t *buf = malloc(fm->len);
    if (!buf) {
        close(fd);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "%s: out of memory", path);
    }
    size_t got = 0;
    while (got < fm->len) {
        ssize_t k = read(fd, buf + got, fm->len - got);
        if (k < 0 && errno == EINTR)
            continue;
        if (k <= 0) {
            int e = k < 0 ? errno : EIO;
            free(buf);
            close(fd);
            return ag_error_set(err, AG_ERR_IO, 0, "cannot read %s: %s", path, strerror(e));
        }
        got += (size_t)k;
    }
    close(fd);
    fm->copy = buf;
    fm->data = buf;
    return AG_OK;
}

void ag_filemap_close(ag_filemap *fm)
{
    if (fm->map)
        munmap(fm->map, fm->len);
    free(fm->copy);
    memset(fm, 0, sizeof *fm);
}
