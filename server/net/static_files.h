/* The web client's files, served from a folder at / (index.html for the folder itself). */
#ifndef AG_STATIC_FILES_H
#define AG_STATIC_FILES_H

#include "request.h"

enum MHD_Result ag_static_serve(ag_request *r, const char *web_dir);

#endif
