/* json_depth.h — how deep a JSON document nests.  Every walker of request
 * data recurses by nesting; bodies deeper than PK_JSON_MAX_DEPTH are refused
 * where they enter (HTTP routes, job files) so no walker meets one. */
#ifndef PK_JSON_DEPTH_H
#define PK_JSON_DEPTH_H

#include <jansson.h>

/* The deepest nesting of objects and arrays accepted in a request or job
 * file: the deepest input of any process nests 6 levels. */
#define PK_JSON_MAX_DEPTH 64

/* 1 when v nests at most max levels of objects/arrays (a scalar is depth 0,
 * {} and [] depth 1); stops walking at max + 1. */
int pk_json_depth_within(const json_t *v, int max);

#endif
