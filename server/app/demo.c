#include "demo.h"

#include "../core/demo_building.h"
#include "../store/models.h"
#include "import_job.h"

ag_status ag_demo_load_if_empty(ag_app *app, ag_error *err)
{
    ag_db *db = ag_app_db(app, err);
    if (!db)
        return err ? err->code : AG_ERR_DB;
    ag_status s = ag_db_begin(db, err);
    if (s != AG_OK)
        return s;
    if (ag_models_count(db) == 0) {
        for (int i = 0; s == AG_OK; i++) {
            ag_mesh *m = ag_demo_building(i);
            if (!m)
                break;
            int64_t id;
            s = ag_import_store_model(db, ag_demo_building_name(i), m, NULL, 0, NULL, &id, err);
            ag_mesh_free(m);
        }
    }
    return s == AG_OK ? ag_db_commit(db, err) : (ag_db_rollback(db), s);
}
