/* Grammar text: what parses prints to a text that parses again to the same print (parse →
 * print → parse → print is a fixed point); what does not parse is refused with a line. */
#include <stddef.h>
#include <stdint.h>

#include "fuzz_check.h"
#include "io/grammar_text.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    ag_grammar *g = NULL;
    ag_error err;
    ag_error_clear(&err);
    long col = 0;
    ag_status s = ag_grammar_text_parse((const char *)data, size, &g, &err, &col);
    if (s != AG_OK) {
        fuzz_check_refusal(s, &err, "grammar");
        return 0;
    }
    char *a = NULL, *b = NULL;
    size_t alen = 0, blen = 0;
    FUZZ_CHECK(ag_grammar_text_print(g, &a, &alen, &err) == AG_OK, "print: %s", err.text);
    ag_grammar *g2 = NULL;
    s = ag_grammar_text_parse(a, alen, &g2, &err, &col);
    FUZZ_CHECK(s == AG_OK, "the printed grammar does not parse (line %ld col %ld): %s\n%s",
               err.element, col, err.text, a);
    FUZZ_CHECK(ag_grammar_text_print(g2, &b, &blen, &err) == AG_OK, "print again: %s", err.text);
    FUZZ_CHECK(alen == blen && memcmp(a, b, alen) == 0, "print is not a fixed point:\n%s\n---\n%s",
               a, b);
    free(a);
    free(b);
    ag_grammar_free(g);
    ag_grammar_free(g2);
    return 0;
}
