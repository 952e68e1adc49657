/* stop_reason.h — why a placement run ended: one vocabulary for RSA, EDMD and
 * tet filling, reported in results and job status by its stable name. */
#ifndef PK_STOP_REASON_H
#define PK_STOP_REASON_H

typedef enum pk_stop_reason {
    PK_STOP_COMPLETE = 0,     /* every grain placed / target reached */
    PK_STOP_MAX_FAILED_DRAWS, /* N^F consecutive failures for one grain */
    PK_STOP_NO_ROOM,          /* a grain does not fit into the box at all */
    PK_STOP_CANCELLED,        /* cancel flag or callback */
    PK_STOP_WALL_TIME,        /* wall-clock limit */
    PK_STOP_JAMMED,           /* (EDMD) jamming criterion met */
    PK_STOP_STALLED,          /* (EDMD) no progress */
    PK_STOP_ERROR,            /* out of memory or invalid input */
    PK_STOP_SATURATED         /* no free space is left for the next grain */
} pk_stop_reason;

/* Stable machine name ("complete", "max_failed_draws", ...). */
const char *pk_stop_reason_name(pk_stop_reason r);

#endif
