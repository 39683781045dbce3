#include "external_ref.h"

/* Enough of a name to recognise it; a longer one is cut with "...". */
#define SHOWN 120

ag_status ag_external_ref_refuse(ag_error *err, long element, const char *where,
                                 const char *name, size_t len)
{
    char shown[SHOWN + 4];
    size_t k = 0;
    for (size_t i = 0; i < len && k < SHOWN; i++) {
        unsigned char c = (unsigned char)name[i];
        shown[k++] = c < 0x20 || c >= 0x7f || c == '"' ? '?' : (char)c;
    }
    if (len > SHOWN)
        for (int i = 0; i < 3; i++)
            shown[k++] = '.';
    shown[k] = '\0';
    return ag_error_set(err, AG_ERR_EXTERNAL_REF, element,
                        "%s: external reference \"%s\" is not allowed in an upload (only the "
                        "uploaded file and inline data: URIs are read)",
                        where, shown);
}
