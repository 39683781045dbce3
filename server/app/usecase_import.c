#include "usecase_import.h"

#include <errno.h>
#include <fcntl.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../io/import.h"
#include "import_sandbox.h"

void ag_usecase_import_release(ag_mesh_file *f)
{
    if (f && f->data && f->len)
        munmap(f->data, f->len);
    if (f)
        memset(f, 0, sizeof *f);
}

static ag_status io_problem(const ag_mesh_source *src, int e, ag_error *err)
{
    return src->what ? ag_error_set(err, AG_ERR_IO, 0, "cannot read %s: %s", src->what, strerror(e))
                     : ag_error_set(err, AG_ERR_IO, 0, "%s", strerror(e));
}

ag_status ag_usecase_import_map(const ag_mesh_source *src, ag_mesh_file *file, ag_error *err)
{
    memset(file, 0, sizeof *file);
    int fd = open(src->path, O_RDONLY | O_CLOEXEC);
    struct stat sb;
    if (fd < 0 || fstat(fd, &sb) != 0) {
        int e = errno;
        if (fd >= 0)
            close(fd);
        return io_problem(src, e, err);
    }
    if (!S_ISREG(sb.st_mode)) {
        close(fd);
        return ag_error_set(err, AG_ERR_IO, 0, "%s%snot a regular file", src->what ? src->what : "",
                            src->what ? " is " : "");
    }
    size_t len = (size_t)sb.st_size;
    if (len == 0) {
        close(fd);
        return src->what ? ag_error_set(err, AG_ERR_EMPTY, 0, "%s is empty", src->what)
                         : ag_error_set(err, AG_ERR_EMPTY, 0, "empty file");
    }
    void *data = mmap(NULL, len, PROT_READ, MAP_PRIVATE, fd, 0);
    int e = errno;
    close(fd);
    if (data == MAP_FAILED)
        return src->what ? ag_error_set(err, AG_ERR_IO, 0, "cannot map %s: %s", src->what,
                                        strerror(e))
                         : io_problem(src, e, err);
    file->data = data;
    file->len = len;
    return AG_OK;
}

ag_status ag_usecase_import_read(const ag_mesh_source *src, int (*progress)(void *, double),
                                 void *user, ag_mesh **mesh, ag_mesh_file *file, ag_error *err)
{
    *mesh = NULL;
    ag_status s = ag_usecase_import_map(src, file, err);
    if (s != AG_OK)
        return s;
    void *data = file->data;
    size_t len = file->len;
    ag_format format = src->format ? ag_format_from_name(src->format)
                                   : ag_format_sniff(data, len,
                                                     src->filename ? src->filename : src->path);
    if (format == AG_FORMAT_UNKNOWN && src->format)
        s = ag_error_set(err, AG_ERR_UNSUPPORTED, 0, "unknown format \"%s\"", src->format);
    else if (format == AG_FORMAT_UNKNOWN && src->format_hint)
        s = ag_error_set(err, AG_ERR_UNSUPPORTED, 0, "the file's format could not be recognised; %s",
                         src->format_hint);
    if (s == AG_OK) {
        ag_import_options iopt = {.up = src->up,
                                  .up_decision = &file->up,
                                  .progress = progress,
                                  .user = user,
                                  .allow_external_files = src->own_file,
                                  .source_path = src->own_file ? src->path : NULL};
        s = format != AG_FORMAT_OBJ
                ? ag_import_sandbox_read(data, len, format, &iopt, src->sandbox_seconds, mesh,
                                         err)
                : ag_import_buffer(data, len, format, &iopt, mesh, err);
    }
    file->format = ag_format_name(format);
    if (s != AG_OK)
        ag_usecase_import_release(file);
    return s;
}

static int on_parse(void *user, double fraction)
{
    return ag_workspace_progress(user, 0.05 + 0.8 * fraction, "parse");
}

ag_status ag_usecase_import_run(ag_workspace *ws, const ag_mesh_source *src, const char *name,
                                int64_t *model, ag_error *err)
{
    *model = 0;
    ag_mesh *mesh = NULL;
    ag_mesh_file file;
    ag_status s = ag_usecase_import_read(src, on_parse, ws, &mesh, &file, err);
    if (s != AG_OK)
        return s;
    if (ag_workspace_progress(ws, 0.9, "store"))
        s = ag_error_set(err, AG_ERR_CANCELLED, 0, "the job was cancelled");
    else
        s = ag_workspace_add_model(ws, name, mesh, file.data, file.len, file.format, &file.up,
                                   model, err);
    ag_mesh_free(mesh);
    ag_usecase_import_release(&file);
    return s;
}
