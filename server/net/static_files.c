#include "static_files.h"

#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static const char *content_type(const char *path)
{
    static const struct {
        const char *ext, *type;
    } types[] = {
        {".html", "text/html; charset=utf-8"},  {".js", "text/javascript; charset=utf-8"},
        {".css", "text/css; charset=utf-8"},    {".map", "application/json"},
        {".json", "application/json"},          {".svg", "image/svg+xml"},
        {".png", "image/png"},                  {".ico", "image/x-icon"},
        {".glb", "model/gltf-binary"},          {".wasm", "application/wasm"},
    };
    const char *dot = strrchr(path, '.');
    for (size_t i = 0; dot && i < sizeof types / sizeof types[0]; i++)
        if (strcmp(dot, types[i].ext) == 0)
            return types[i].type;
    return "application/octet-stream";
}

/* Only plain relative names: letters, digits, '-', '_', '.', '/' and no "..". */
static int safe_path(const char *p)
{
    if (strstr(p, ".."))
        return 0;
    for (; *p; p++) {
        char c = *p;
        if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
              c == '-' || c == '_' || c == '.' || c == '/'))
            return 0;
    }
    return 1;
}

enum MHD_Result ag_static_serve(ag_request *r, const char *web_dir)
{
    ag_error err;
    if (strcmp(r->method, "GET") != 0 && strcmp(r->method, "HEAD") != 0) {
        ag_reply_header(r, MHD_HTTP_HEADER_ALLOW, "GET, HEAD");
        ag_error_set(&err, AG_ERR_METHOD_NOT_ALLOWED, 0, "%s accepts GET and HEAD", r->url);
        return ag_reply_problem(r, AG_ERR_METHOD_NOT_ALLOWED, &err);
    }
    if (!web_dir) {
        ag_error_set(&err, AG_ERR_NOT_FOUND, 0, "this archgramd serves no web client (--web)");
        return ag_reply_problem(r, AG_ERR_NOT_FOUND, &err);
    }
    const char *rel = r->url + 1;
    if (*rel == '\0')
        rel = "index.html";
    char path[4096];
    struct stat st;
    int fd = -1;
    if (safe_path(rel) && snprintf(path, sizeof path, "%s/%s", web_dir, rel) < (int)sizeof path &&
        (fd = open(path, O_RDONLY | O_CLOEXEC)) >= 0 && fstat(fd, &st) == 0 &&
        S_ISREG(st.st_mode)) {
        struct MHD_Response *resp = MHD_create_response_from_fd((uint64_t)st.st_size, fd);
        if (!resp) {
            close(fd);
            return MHD_NO;
        }
        MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE, content_type(path));
        MHD_add_response_header(resp, MHD_HTTP_HEADER_CACHE_CONTROL, "no-cache");
        enum MHD_Result rc = MHD_queue_response(r->conn, MHD_HTTP_OK, resp);
        MHD_destroy_response(resp);
        return rc;
    }
    if (fd >= 0)
        close(fd);
    ag_error_set(&err, AG_ERR_NOT_FOUND, 0, "no file at %s", r->url);
    return ag_reply_problem(r, AG_ERR_NOT_FOUND, &err);
}
