/* Demo content for `make run`: the generated buildings, stored when the database is empty. */
#ifndef AG_DEMO_H
#define AG_DEMO_H

#include "app.h"

ag_status ag_demo_load_if_empty(ag_app *app, ag_error *err);

#endif
