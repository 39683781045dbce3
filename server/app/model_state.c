#include "model_state.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/base/clock.h"
#include "../io/grammar_text.h"
#include "model_kept.h"

void ag_model_state_clear(ag_model_state *s)
{
    if (!s)
        return;
    ag_model_state_checked(s, NULL); /* a check still running is waited for */
    free(s->text);
    ag_terminals_set_clear(&s->terms);
    ag_mesh_free(s->derived);
    ag_edit_model_free(s->em);
    memset(s, 0, sizeof *s);
}

/* Line and column of "terminal NAME" in the text (1, 1 when it cannot be found). */
static void find_declaration(const char *text, size_t len, const char *name, long *line,
                             long *col)
{
    *line = 1;
    *col = 1;
    size_t nl = strlen(name);
    long ln = 1;
    for (size_t i = 0; i < len;) {
        size_t s = i;
        while (s < len && (text[s] == ' ' || text[s] == '\t'))
            s++;
        if (len - s > 9 + nl && memcmp(text + s, "terminal", 8) == 0 &&
            (text[s + 8] == ' ' || text[s + 8] == '\t')) {
            size_t n = s + 8;
            while (n < len && (text[n] == ' ' || text[n] == '\t'))
                n++;
            if (len - n >= nl && memcmp(text + n, name, nl) == 0 &&
                (n + nl == len || text[n + nl] == ' ' || text[n + nl] == '\t' ||
                 text[n + nl] == '\r' || text[n + nl] == '\n')) {
                *line = ln;
                *col = (long)(s - i) + 1;
                return;
            }
        }
        while (i < len && text[i] != '\n')
            i++;
        i++;
        ln++;
    }
}

/* Parses text, loads every terminal through lookup and derives the mesh (at most
 * max_triangles). */
static ag_status derive_text(const char *text, size_t len, ag_terminal_lookup lookup, void *user,
                             size_t max_triangles, ag_grammar **g, ag_mesh **mesh, ag_error *err,
                             long *col)
{
    *g = NULL;
    *mesh = NULL;
    if (col)
        *col = 0;
    long c = 0;
    ag_status s = ag_grammar_text_parse(text, len, g, err, &c);
    if (s != AG_OK) {
        if (col)
            *col = c;
        /* name and resolve errors come with a position too: all are the text's fault */
        if (s != AG_ERR_NOMEM && err && err->element > 0)
            err->code = s = AG_ERR_PARSE;
        return s;
    }
    for (size_t i = 0; i < (*g)->nterminals && s == AG_OK; i++) {
        ag_gterminal *t = &(*g)->terminals[i];
        char *obj = NULL;
        size_t olen = 0;
        ag_error e;
        ag_error_clear(&e);
        s = t->path ? lookup(user, t->path, &obj, &olen, &e) : AG_ERR_NOT_FOUND;
        if (s == AG_ERR_NOT_FOUND) {
            long line, cc;
            find_declaration(text, len, t->name, &line, &cc);
            if (col)
                *col = cc;
            s = ag_error_set(err, AG_ERR_PARSE, line,
                             "terminal '%s' names \"%s\", which is not one of this model's "
                             "terminals",
                             t->name, t->path ? t->path : "");
        } else if (s != AG_OK) {
            if (err)
                *err = e;
        } else {
            s = ag_terminals_load_buffer(t, obj, olen, err);
        }
        free(obj);
    }
    ag_grammar_derive_options dopt = {.max_triangles = max_triangles};
    if (s == AG_OK)
        s = ag_grammar_derive(*g, &dopt, mesh, err);
    if (s != AG_OK) {
        ag_grammar_free(*g);
        *g = NULL;
    }
    return s;
}

/* r's mesh grouped by r's labels, named as the grammar export names them. */
static ag_status regroup(ag_proceduralize_result *r, ag_error *err)
{
    if (ag_labels_name_groups(r->mesh, r->labels) != AG_OK)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory naming the labels");
    return AG_OK;
}

/* Grammar g printed (*text) and read back: the text parsed with the terminals of terms and
 * derived (*derived, at most max_triangles); a text that does not is AG_ERR_INTERNAL. */
static ag_status print_and_read_back(const ag_grammar *g, const ag_terminal_set *terms,
                                     size_t max_triangles, char **text, size_t *len,
                                     ag_mesh **derived, ag_error *err)
{
    ag_grammar *back = NULL;
    long col = 0;
    ag_error e;
    ag_error_clear(&e);
    ag_status s = ag_grammar_text_print(g, text, len, err);
    if (s == AG_OK &&
        (s = derive_text(*text, *len, ag_terminals_set_lookup, (void *)terms, max_triangles,
                         &back, derived, &e, &col)) != AG_OK)
        s = ag_error_set(err, s == AG_ERR_NOMEM ? s : AG_ERR_INTERNAL, 0,
                         "the grammar does not read back (line %ld, column %ld): %s", e.element,
                         col, e.text);
    ag_grammar_free(back);
    return s;
}

/* out's terminals (g's paths set as they will be kept), text and read-back. */
static ag_status read_back(ag_grammar *g, ag_model_state *out, ag_error *err)
{
    ag_status s = ag_terminals_collect(g, &out->terms, err);
    return s == AG_OK ? print_and_read_back(g, &out->terms, AG_GRAMMAR_MAX_TRIANGLES, &out->text,
                                            &out->text_len, &out->derived, err)
                      : s;
}

/* A read-back check running beside the caller (ag_model_state_start,
 * ag_model_state_from_grammar_start). */
struct ag_model_state_check {
    pthread_t thread;
    const ag_grammar *grammar;
    ag_grammar *owned;     /* the grammar when the check has it to itself: freed after */
    const ag_mesh *expect; /* the derivation the state keeps: the text must derive it (or
                              NULL: what the text derives is kept) */
    size_t max_triangles;
    ag_model_state *out;
    double ms;
    ag_status status;
    ag_error err;
};

static void *run_check(void *arg)
{
    struct ag_model_state_check *c = arg;
    ag_model_state *out = c->out;
    double t0 = ag_clock_ms();
    ag_error_clear(&c->err);
    ag_mesh *back = NULL;
    c->status = print_and_read_back(c->grammar, &out->terms, c->max_triangles, &out->text,
                                    &out->text_len, c->expect ? &back : &out->derived, &c->err);
    const char *diff = c->status == AG_OK && c->expect ? ag_mesh_difference(c->expect, back) : "";
    if (*diff)
        c->status = ag_error_set(&c->err, AG_ERR_INTERNAL, 0,
                                 "the grammar read back derives another mesh than the grammar "
                                 "made: %s differ",
                                 diff);
    ag_mesh_free(back);
    c->ms = ag_clock_ms() - t0;
    return NULL;
}

/* Starts c on out (c->out set here): AG_OK once it runs, else c is freed and the caller
 * checks on its own thread. */
static int check_started(struct ag_model_state_check *c, ag_model_state *out)
{
    if (!c)
        return 0;
    c->out = out;
    if (pthread_create(&c->thread, NULL, run_check, c) == 0) {
        out->check = c;
        return 1;
    }
    return 0;
}

ag_status ag_model_state_start(ag_edit_model **made, unsigned flags, ag_model_state *out,
                               ag_error *err)
{
    if (flags & AG_MODEL_READ_BACK)
        return ag_model_state_make(made, flags, out, err);
    memset(out, 0, sizeof *out);
    ag_edit_model *m = *made;
    ag_status s = regroup(m->proc, err);
    if (s == AG_OK) /* sets the grammar's terminal paths: before anything reads it beside */
        s = ag_terminals_collect(m->proc->grammar, &out->terms, err);
    if (s != AG_OK) {
        ag_terminals_set_clear(&out->terms);
        return s;
    }
    struct ag_model_state_check *c = calloc(1, sizeof *c);
    out->em = m;
    *made = NULL;
    if (c) { /* the check reads the grammar only; the caller reads the tree and the mesh */
        c->grammar = m->proc->grammar;
        c->max_triangles = AG_GRAMMAR_MAX_TRIANGLES;
        if (check_started(c, out))
            return AG_OK;
        free(c);
    }
    if ((s = print_and_read_back(m->proc->grammar, &out->terms, AG_GRAMMAR_MAX_TRIANGLES,
                                 &out->text, &out->text_len, &out->derived, err)) != AG_OK)
        ag_model_state_clear(out);
    return s;
}

ag_status ag_model_state_checked(ag_model_state *st, ag_error *err)
{
    struct ag_model_state_check *c = st->check;
    if (!c)
        return AG_OK;
    pthread_join(c->thread, NULL);
    st->check = NULL;
    st->times.check_ms = c->ms;
    ag_status s = c->status;
    if (s != AG_OK && err)
        *err = c->err;
    ag_grammar_free(c->owned);
    free(c);
    return s;
}

/* The work done beside the read-back's proceduralization, on a thread of its own. */
typedef struct {
    ag_model_state_beside fn;
    void *user;
    const ag_mesh *derived;
    ag_status status;
    ag_error err;
} beside_work;

static void *run_beside(void *arg)
{
    beside_work *b = arg;
    b->status = b->fn(b->user, b->derived, &b->err);
    return NULL;
}

ag_status ag_model_state_make(ag_edit_model **made, unsigned flags, ag_model_state *out,
                              ag_error *err)
{
    return ag_model_state_make_beside(made, flags, NULL, NULL, out, err);
}

ag_status ag_model_state_make_beside(ag_edit_model **made, unsigned flags,
                                     ag_model_state_beside beside, void *user,
                                     ag_model_state *out, ag_error *err)
{
    memset(out, 0, sizeof *out);
    ag_edit_model *m = *made;
    ag_status s = read_back(m->proc->grammar, out, err);
    beside_work bw = {.fn = beside, .user = user, .derived = out->derived};
    pthread_t thread;
    /* the derivation is only read from here on: the reload and the work beside share it */
    int threaded = s == AG_OK && beside && (flags & AG_MODEL_READ_BACK) &&
                   pthread_create(&thread, NULL, run_beside, &bw) == 0;
    if (s == AG_OK && beside && !threaded) { /* before *made is moved: a failure keeps it */
        run_beside(&bw);
        s = bw.status;
        bw.status = AG_OK;
        if (s != AG_OK && err)
            *err = bw.err;
    }
    if (s == AG_OK && (flags & AG_MODEL_READ_BACK)) {
        s = ag_model_state_reload(out->derived, &out->em, err);
    } else if (s == AG_OK && (s = regroup(m->proc, err)) == AG_OK) {
        out->em = m;
        *made = NULL;
    }
    if (threaded)
        pthread_join(thread, NULL);
    if (s == AG_OK && beside && bw.status != AG_OK) {
        s = bw.status;
        if (err)
            *err = bw.err;
    }
    if (s != AG_OK)
        ag_model_state_clear(out);
    return s;
}

static int budget_stage(void *budget, ag_stage stage)
{
    (void)stage;
    return ag_edit_budget_cancelled(budget);
}

ag_status ag_model_state_from_grammar(ag_grammar *g, size_t max_triangles, ag_model_state *out,
                                      ag_error *err)
{
    return ag_model_state_from_grammar_ex(g, max_triangles, NULL, NULL, out, err);
}

ag_status ag_model_state_from_grammar_ex(ag_grammar *g, size_t max_triangles,
                                         ag_model_state_maker make, void *user,
                                         ag_model_state *out, ag_error *err)
{
    memset(out, 0, sizeof *out);
    ag_model_state_times *tm = &out->times;
    ag_grammar *back = NULL;
    long col = 0;
    ag_error e;
    ag_error_clear(&e);
    double t0 = ag_clock_ms();
    ag_status s = ag_terminals_collect(g, &out->terms, err);
    double t1 = ag_clock_ms();
    tm->terminals_ms = t1 - t0;
    if (s == AG_OK)
        s = ag_grammar_text_print(g, &out->text, &out->text_len, err);
    t0 = ag_clock_ms();
    tm->text_ms = t0 - t1;
    if (s == AG_OK &&
        (s = derive_text(out->text, out->text_len, ag_terminals_set_lookup, &out->terms,
                         max_triangles ? max_triangles : AG_GRAMMAR_MAX_TRIANGLES, &back,
                         &out->derived, &e, &col)) != AG_OK) {
        if (s == AG_ERR_TOO_LARGE)
            ag_error_set(err, s, 0, "the grammar derives more than %zu triangles",
                         max_triangles ? max_triangles : AG_GRAMMAR_MAX_TRIANGLES);
        else
            s = ag_error_set(err, s == AG_ERR_NOMEM ? s : AG_ERR_INTERNAL, 0,
                             "the grammar does not read back (line %ld, column %ld): %s",
                             e.element, col, e.text);
    }
    ag_grammar_free(back);
    t1 = ag_clock_ms();
    tm->read_back_ms = t1 - t0;
    if (s == AG_OK && !out->derived->ntris)
        s = ag_error_set(err, AG_ERR_EMPTY, 0, "the grammar derives no geometry");
    if (s == AG_OK)
        s = make ? make(user, out->derived, &out->em, err)
                 : ag_model_state_reload(out->derived, &out->em, err);
    tm->model_ms = ag_clock_ms() - t1;
    if (s != AG_OK)
        ag_model_state_clear(out);
    return s;
}

/* g's terminals given the geometry their kept text (terms) reads as, so that g derives what
 * the kept grammar does. */
static ag_status load_kept_terminals(ag_grammar *g, const ag_terminal_set *terms, ag_error *err)
{
    ag_status s = AG_OK;
    /* terms was collected from g in its order: each search starts where the last one ended,
     * so a grammar's terminals are found in one pass, not one scan each */
    size_t from = 0;
    for (size_t i = 0; i < g->nterminals && s == AG_OK; i++) {
        ag_gterminal *t = &g->terminals[i];
        size_t k = terms->n, tries = 0;
        for (size_t j = from; tries < terms->n; tries++, j = j + 1 < terms->n ? j + 1 : 0)
            if (!strcmp(terms->path[j], t->path)) {
                k = j;
                break;
            }
        if (k < terms->n)
            from = k;
        s = k < terms->n ? ag_terminals_load_buffer(t, terms->obj[k], terms->len[k], err)
                         : ag_error_set(err, AG_ERR_INTERNAL, 0,
                                        "terminal '%s' was not collected", t->name);
    }
    return s;
}

ag_status ag_model_state_from_grammar_start(ag_grammar **grammar, size_t max_triangles,
                                            ag_model_state_maker make, void *user,
                                            ag_model_state *out, ag_error *err)
{
    memset(out, 0, sizeof *out);
    ag_model_state_times *tm = &out->times;
    ag_grammar *g = *grammar;
    size_t max = max_triangles ? max_triangles : AG_GRAMMAR_MAX_TRIANGLES;
    double t0 = ag_clock_ms();
    ag_status s = ag_terminals_collect(g, &out->terms, err);
    if (s == AG_OK)
        s = load_kept_terminals(g, &out->terms, err);
    if (s == AG_OK)
        ag_grammar_text_round(g);
    double t1 = ag_clock_ms();
    tm->terminals_ms = t1 - t0;
    ag_grammar_derive_options dopt = {.max_triangles = max};
    if (s == AG_OK && (s = ag_grammar_derive(g, &dopt, &out->derived, err)) == AG_ERR_TOO_LARGE)
        ag_error_set(err, s, 0, "the grammar derives more than %zu triangles", max);
    t0 = ag_clock_ms();
    tm->read_back_ms = t0 - t1;
    if (s == AG_OK && !out->derived->ntris)
        s = ag_error_set(err, AG_ERR_EMPTY, 0, "the grammar derives no geometry");
    struct ag_model_state_check *c = s == AG_OK ? calloc(1, sizeof *c) : NULL;
    if (c) { /* the check has the grammar to itself; it and the maker only read the derivation */
        *c = (struct ag_model_state_check){
            .grammar = g, .owned = g, .expect = out->derived, .max_triangles = max};
        if (check_started(c, out))
            *grammar = NULL;
        else
            free(c);
    }
    if (s == AG_OK && !out->check) { /* no thread: checked here, before the model is made */
        struct ag_model_state_check here = {
            .grammar = g, .expect = out->derived, .max_triangles = max, .out = out};
        run_check(&here);
        if ((s = here.status) != AG_OK && err)
            *err = here.err;
        tm->check_ms = here.ms;
        t0 = ag_clock_ms();
    }
    if (s == AG_OK)
        s = make ? make(user, out->derived, &out->em, err)
                 : ag_model_state_reload(out->derived, &out->em, err);
    tm->model_ms = ag_clock_ms() - t0;
    if (s != AG_OK)
        ag_model_state_clear(out);
    return s;
}

ag_status ag_model_state_from_text(const char *text, size_t len, ag_terminal_lookup lookup,
                                   void *user, const ag_edit_budget *budget,
                                   ag_model_state *out, ag_error *err, long *col)
{
    memset(out, 0, sizeof *out);
    ag_grammar *g = NULL;
    size_t max_tris = budget && budget->max_triangles && budget->max_triangles <
                                                             AG_GRAMMAR_MAX_TRIANGLES
                          ? budget->max_triangles
                          : AG_GRAMMAR_MAX_TRIANGLES;
    ag_status s = derive_text(text, len, lookup, user, max_tris, &g, &out->derived, err, col);
    if (s == AG_ERR_TOO_LARGE && max_tris < AG_GRAMMAR_MAX_TRIANGLES)
        s = ag_error_set(err, AG_ERR_RESULT_TOO_LARGE, err ? err->element : 0,
                         "the grammar derives more than %zu triangles, the most this server "
                         "takes",
                         max_tris);
    if (s == AG_OK && budget && budget->max_components &&
        out->derived->ncomponents > budget->max_components)
        s = ag_error_set(err, AG_ERR_RESULT_TOO_LARGE, 0,
                         "the grammar places %zu terminals; this server takes at most %zu",
                         out->derived->ncomponents, budget->max_components);
    if (s != AG_OK) {
        ag_grammar_free(g);
        ag_model_state_clear(out);
        return s;
    }
    if (s != AG_OK)
        return s;
    if (!(out->text = malloc(len + 1)))
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    else {
        memcpy(out->text, text, len);
        out->text[len] = '\0';
        out->text_len = len;
    }
    ag_grammar_free(g);
    if (s == AG_OK && budget && budget->cancelled) {
        ag_proceduralize_options po = {.progress = budget_stage, .user = (void *)budget};
        s = ag_edit_model_create(out->derived, &po, &out->em, err);
    } else if (s == AG_OK) {
        s = ag_model_state_reload(out->derived, &out->em, err);
    }
    if (s != AG_OK)
        ag_model_state_clear(out);
    return s;
}

ag_status ag_model_state_reload(const ag_mesh *mesh, ag_edit_model **em, ag_error *err)
{
    return ag_edit_model_create(mesh, NULL, em, err);
}

ag_status ag_model_state_reload_kept(const ag_mesh *mesh, const char *tree_text,
                                     ag_edit_model **em, ag_error *err)
{
    if (!tree_text)
        return ag_model_state_reload(mesh, em, err);
    ag_status s = ag_model_kept_reload(mesh, tree_text, em, err);
    if (s == AG_ERR_NOT_FOUND) /* a tree stored before models were kept with it */
        s = ag_model_state_reload(mesh, em, err);
    return s;
}
