/* json_depth.c — nesting depth of a JSON document.
 * Contract: api/inputs/json_depth.h. */
#include "json_depth.h"

static int within(const json_t *v, int left)
{
    if (!json_is_object(v) && !json_is_array(v))
        return 1;
    if (left <= 0)
        return 0;
    if (json_is_object(v)) {
        const char *key;
        json_t *child;
        json_object_foreach ((json_t *)v, key, child)
            if (!within(child, left - 1))
                return 0;
    } else {
        size_t i;
        json_t *child;
        json_array_foreach (v, i, child)
            if (!within(child, left - 1))
                return 0;
    }
    return 1;
}

int pk_json_depth_within(const json_t *v, int max) { return within(v, max); }
