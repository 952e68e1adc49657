/* stop_reason.c — the stable machine names of the reasons a placement run ends.
 * Contract: core/base/stop_reason.h. */
#include "stop_reason.h"

const char *pk_stop_reason_name(pk_stop_reason r)
{
    switch (r) {
    case PK_STOP_COMPLETE: return "complete";
    case PK_STOP_MAX_FAILED_DRAWS: return "max_failed_draws";
    case PK_STOP_NO_ROOM: return "no_room";
    case PK_STOP_CANCELLED: return "cancelled";
    case PK_STOP_WALL_TIME: return "wall_time";
    case PK_STOP_JAMMED: return "jammed";
    case PK_STOP_STALLED: return "stalled";
    case PK_STOP_ERROR: return "error";
    case PK_STOP_SATURATED: return "saturated";
    }
    return "unknown";
}
