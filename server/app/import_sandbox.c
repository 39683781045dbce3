#include "import_sandbox.h"

#include <errno.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "../io/meshblob.h"

#if defined(__SANITIZE_ADDRESS__)
#define SANDBOX_CAP 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SANDBOX_CAP 0
#endif
#endif
#ifndef SANDBOX_CAP
#define SANDBOX_CAP 1
#endif

/* What the child writes first: the outcome and the up axis it decided (the parent reports
 * it), then blob_len bytes of meshblob. */
typedef struct {
    uint32_t magic;
    int32_t status;
    int64_t element;
    uint64_t blob_len;
    char text[AG_ERROR_TEXT];
    ag_up_decision up;
} reply_head;

#define REPLY_MAGIC 0x61677362u /* "agsb" */

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

static int write_all(int fd, const void *p, size_t n)
{
    const char *c = p;
    while (n) {
        ssize_t k = write(fd, c, n);
        if (k < 0 && errno == EINTR)
            continue;
        if (k <= 0)
            return -1;
        c += k;
        n -= (size_t)k;
    }
    return 0;
}

/* The parent's address space now (bytes), to cap the child's above it. */
static size_t vm_size(void)
{
    FILE *f = fopen("/proc/self/statm", "r");
    unsigned long pages = 0;
    if (f) {
        if (fscanf(f, "%lu", &pages) != 1)
            pages = 0;
        fclose(f);
    }
    return (size_t)pages * (size_t)sysconf(_SC_PAGESIZE);
}

static void child(int fd, const uint8_t *data, size_t len, ag_format fmt,
                  const ag_import_options *caller, size_t cap, double seconds, pid_t parent)
{
    /* never outlive the parent (it would hold the service's sockets), nor the deadline's
     * worth of processor time should the parent stop watching */
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent)
        _exit(4); /* the parent went before the signal was asked for */
    /* a crash of the importer kills the child by its signal, which the parent reports as a
     * refusal of the file; handlers inherited from the parent (a sanitizer's, a fuzzer's)
     * would turn it into an exit code instead */
    static const int fatal[] = {SIGABRT, SIGSEGV, SIGBUS, SIGFPE, SIGILL};
    for (size_t i = 0; i < sizeof fatal / sizeof fatal[0]; i++)
        signal(fatal[i], SIG_DFL);
    if (seconds > 0) {
        rlim_t cpu = (rlim_t)seconds + 2;
        struct rlimit rl = {cpu, cpu};
        setrlimit(RLIMIT_CPU, &rl);
    }
    if (SANDBOX_CAP && cap) {
        struct rlimit rl = {cap, cap};
        setrlimit(RLIMIT_AS, &rl);
    }
    reply_head h = {.magic = REPLY_MAGIC};
    /* no progress (it writes the parent's store); files beside the main one only when the
     * caller allows them (the command line's own files, never an upload's) */
    ag_import_options o = {.up = caller ? caller->up : AG_UP_DEFAULT,
                           .up_decision = &h.up,
                           .allow_external_files = caller && caller->allow_external_files,
                           .source_path = caller ? caller->source_path : NULL};
    ag_mesh *m = NULL;
    ag_error err;
    ag_error_clear(&err);
    uint8_t *blob = NULL;
    size_t blob_len = 0;
    ag_status s = ag_import_buffer(data, len, fmt, &o, &m, &err);
    if (s == AG_OK && (s = ag_meshblob_encode(m, &blob, &blob_len)) != AG_OK)
        ag_error_set(&err, s, 0, "out of memory encoding the mesh");
    h.status = s;
    h.element = err.element;
    memcpy(h.text, err.text, sizeof h.text);
    h.blob_len = s == AG_OK ? blob_len : 0;
    int ok = write_all(fd, &h, sizeof h) == 0 &&
             (!h.blob_len || write_all(fd, blob, blob_len) == 0);
    _exit(ok ? 0 : 3);
}

ag_status ag_import_sandbox_read(const uint8_t *data, size_t len, ag_format fmt,
                                 const ag_import_options *opt, double seconds, ag_mesh **out,
                                 ag_error *err)
{
    *out = NULL;
    int fds[2];
    if (pipe(fds) != 0)
        return ag_error_set(err, AG_ERR_INTERNAL, 0, "cannot start the importer: %s",
                            strerror(errno));
    size_t cap = vm_size() + AG_IMPORT_SANDBOX_EXTRA_BYTES;
    fflush(NULL);
    pid_t parent = getpid(), pid = fork();
    if (pid < 0) {
        int e = errno;
        close(fds[0]);
        close(fds[1]);
        return ag_error_set(err, AG_ERR_INTERNAL, 0, "cannot start the importer: %s",
                            strerror(e));
    }
    if (pid == 0) {
        close(fds[0]);
        child(fds[1], data, len, fmt, opt, cap, seconds, parent);
    }
    close(fds[1]);
    /* read the reply until the child closes the pipe, within the deadline */
    double t0 = now(), last_ask = t0;
    reply_head h;
    size_t got = 0, want = sizeof h;
    uint8_t *blob = NULL;
    ag_status s = AG_OK;
    int ended = 0;
    while (!ended && s == AG_OK) {
        double t = now();
        if (seconds > 0 && t - t0 > seconds) {
            s = ag_error_set(err, AG_ERR_DEADLINE, 0,
                             "reading the file took longer than %g s and was stopped", seconds);
            break;
        }
        if (opt && opt->progress && t - last_ask > 0.1) {
            last_ask = t;
            double f = seconds > 0 ? (t - t0) / seconds : 0.5;
            if (opt->progress(opt->user, f < 0.9 ? f : 0.9)) {
                s = ag_error_set(err, AG_ERR_CANCELLED, 0, "the import was cancelled");
                break;
            }
        }
        struct pollfd p = {.fd = fds[0], .events = POLLIN};
        int r = poll(&p, 1, 100);
        if (r < 0 && errno != EINTR) {
            s = ag_error_set(err, AG_ERR_INTERNAL, 0, "waiting for the importer: %s",
                             strerror(errno));
            break;
        }
        if (r <= 0)
            continue;
        uint8_t *dst = got < sizeof h ? (uint8_t *)&h + got : blob + (got - sizeof h);
        ssize_t k = read(fds[0], dst, want - got);
        if (k < 0 && errno == EINTR)
            continue;
        if (k <= 0) {
            ended = 1; /* the child is done (or gone) */
            break;
        }
        got += (size_t)k;
        if (got == sizeof h && want == sizeof h) {
            if (h.magic != REPLY_MAGIC) {
                s = ag_error_set(err, AG_ERR_INTERNAL, 0, "the importer's answer is garbled");
                break;
            }
            want += h.blob_len;
            if (h.blob_len && !(blob = malloc(h.blob_len)))
                s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory reading the mesh");
        }
        if (got == want && got >= sizeof h)
            ended = 1;
    }
    close(fds[0]);
    if (!ended)
        kill(pid, SIGKILL);
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR)
        ;
    if (s == AG_OK) {
        if (got < sizeof h) {
            /* it died before answering: the file took the importer down */
            if (WIFSIGNALED(status))
                s = ag_error_set(err, AG_ERR_PARSE, 0,
                                 "the importer crashed on this file (%s): the file is "
                                 "malformed or uses what the importer cannot read",
                                 strsignal(WTERMSIG(status)));
            else
                s = ag_error_set(err, AG_ERR_INTERNAL, 0,
                                 "the importer stopped without an answer (exit %d)",
                                 WIFEXITED(status) ? WEXITSTATUS(status) : -1);
        } else if (got < want) {
            s = ag_error_set(err, AG_ERR_INTERNAL, 0, "the importer's answer was cut short");
        } else if (h.status != AG_OK) {
            h.text[sizeof h.text - 1] = '\0';
            s = ag_error_set(err, (ag_status)h.status, (long)h.element, "%s", h.text);
        } else {
            s = ag_meshblob_decode(blob, h.blob_len, out, err);
            if (s == AG_OK && opt && opt->up_decision)
                *opt->up_decision = h.up;
        }
    }
    free(blob);
    return s;
}
