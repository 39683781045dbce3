#include "upload.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

struct ag_upload {
    int fd;
    char path[4096];
    int owned; /* 1 while the file is ours to delete */
    size_t bytes, limit;
    struct MHD_PostProcessor *pp;
    int saw_file;
    ag_status status; /* first failure inside the multipart iterator */
    ag_error err;
    char name[801];
    char filename[256];
};

static ag_status write_all(ag_upload *u, const char *data, size_t len, ag_error *err)
{
    if (u->bytes + len > u->limit)
        return ag_error_set(err, AG_ERR_TOO_LARGE, 0,
                            "the upload is larger than the limit of %zu bytes", u->limit);
    while (len) {
        ssize_t n = write(u->fd, data, len);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            return ag_error_set(err, AG_ERR_IO, 0, "cannot spool the upload: %s",
                                strerror(errno));
        data += n;
        len -= (size_t)n;
        u->bytes += (size_t)n;
    }
    return AG_OK;
}

static enum MHD_Result on_part(void *cls, enum MHD_ValueKind kind, const char *key,
                               const char *filename, const char *content_type,
                               const char *transfer_encoding, const char *data, uint64_t off,
                               size_t size)
{
    (void)kind, (void)content_type, (void)transfer_encoding, (void)off;
    ag_upload *u = cls;
    if (!key)
        return MHD_YES;
    if (strcmp(key, "file") == 0) {
        u->saw_file = 1;
        if (filename && !u->filename[0])
            snprintf(u->filename, sizeof u->filename, "%s", filename);
        if (size && (u->status = write_all(u, data, size, &u->err)) != AG_OK)
            return MHD_NO;
    } else if (strcmp(key, "name") == 0) {
        size_t have = strlen(u->name);
        if (have + size >= sizeof u->name) {
            u->status = ag_error_set(&u->err, AG_ERR_INVALID, 0, "the name part is too long");
            return MHD_NO;
        }
        memcpy(u->name + have, data, size);
        u->name[have + size] = '\0';
    }
    return MHD_YES;
}

ag_status ag_upload_begin(ag_request *r, ag_upload **out, ag_error *err)
{
    *out = NULL;
    ag_upload *u = calloc(1, sizeof *u);
    if (!u)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    u->fd = -1;
    u->limit = r->cfg->max_body;
    snprintf(u->path, sizeof u->path, "%s/upload-XXXXXX", ag_app_upload_dir(r->cfg->app));
    u->fd = mkstemp(u->path);
    if (u->fd < 0) {
        free(u);
        return ag_error_set(err, AG_ERR_IO, 0, "cannot create a file for the upload: %s",
                            strerror(errno));
    }
    u->owned = 1;
    const char *type = ag_request_header(r, MHD_HTTP_HEADER_CONTENT_TYPE);
    if (type && strncasecmp(type, "multipart/form-data", 19) == 0) {
        u->pp = MHD_create_post_processor(r->conn, 64 * 1024, on_part, u);
        if (!u->pp) {
            ag_upload_free(u);
            return ag_error_set(err, AG_ERR_INVALID, 0,
                                "the multipart/form-data body has no usable boundary");
        }
    }
    *out = u;
    return AG_OK;
}

ag_status ag_upload_feed(ag_upload *u, const char *data, size_t len, ag_error *err)
{
    if (!u->pp)
        return write_all(u, data, len, err);
    if (MHD_post_process(u->pp, data, len) != MHD_YES) {
        if (u->status != AG_OK) {
            if (err)
                *err = u->err;
            return u->status;
        }
        return ag_error_set(err, AG_ERR_INVALID, 0, "the multipart/form-data body is malformed");
    }
    return AG_OK;
}

ag_status ag_upload_end(ag_upload *u, ag_error *err)
{
    if (u->pp) {
        MHD_destroy_post_processor(u->pp);
        u->pp = NULL;
        if (u->status != AG_OK) {
            if (err)
                *err = u->err;
            return u->status;
        }
        if (!u->saw_file)
            return ag_error_set(err, AG_ERR_INVALID, 0,
                                "the multipart/form-data body has no part named \"file\"");
    }
    if (u->fd >= 0) {
        close(u->fd);
        u->fd = -1;
    }
    return AG_OK;
}

void ag_upload_free(ag_upload *u)
{
    if (!u)
        return;
    if (u->pp)
        MHD_destroy_post_processor(u->pp);
    if (u->fd >= 0)
        close(u->fd);
    if (u->owned)
        unlink(u->path);
    free(u);
}

size_t ag_upload_bytes(const ag_upload *u) { return u->bytes; }
const char *ag_upload_form_name(const ag_upload *u) { return u->name[0] ? u->name : NULL; }
const char *ag_upload_filename(const ag_upload *u) { return u->filename[0] ? u->filename : NULL; }

void ag_upload_name(ag_request *r, const char *fallback, char *buf, size_t len)
{
    const char *name = ag_request_query(r, "name");
    if (!name)
        name = ag_upload_form_name(r->upload);
    if (name) {
        snprintf(buf, len, "%s", name);
        return;
    }
    const char *file = ag_upload_filename(r->upload);
    snprintf(buf, len, "%s", file ? file : fallback);
    char *dot = strrchr(buf, '.');
    if (dot && dot != buf)
        *dot = '\0';
}

const char *ag_upload_take_path(ag_upload *u)
{
    u->owned = 0;
    return u->path;
}

ag_status ag_upload_read_all(ag_request *r, size_t max, const char *what, char **text,
                             size_t *len, ag_error *err)
{
    *text = NULL;
    *len = 0;
    size_t n = r->upload ? ag_upload_bytes(r->upload) : 0;
    if (n > max)
        return ag_error_set(err, AG_ERR_TOO_LARGE, 0,
                            "the %s has %zu bytes; at most %zu are accepted", what, n, max);
    if (n == 0)
        return ag_error_set(err, AG_ERR_INVALID, 0, "the body must hold the %s", what);
    const char *path = ag_upload_take_path(r->upload);
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    char *buf = malloc(n + 1);
    size_t got = 0;
    while (fd >= 0 && buf && got < n) {
        ssize_t k = read(fd, buf + got, n - got);
        if (k <= 0)
            break;
        got += (size_t)k;
    }
    int e = errno;
    if (fd >= 0)
        close(fd);
    unlink(path);
    if (!buf)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory reading the body");
    if (got != n) {
        free(buf);
        return ag_error_set(err, AG_ERR_IO, 0, "cannot read the body back: %s", strerror(e));
    }
    buf[n] = '\0';
    *text = buf;
    *len = n;
    return AG_OK;
}
