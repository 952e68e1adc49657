/* check_ctx.h — where the inputs being checked come from.  The semantic
 * checks of a process (process.h) are the same for a job file and for a
 * request to the daemon, except for files: a job file on the user's own
 * machine (`packd run`, `packd validate`, the daemon's workers) has its mesh
 * read and checked and its RVE file opened (pk_input_check); a request to the daemon is checked in the HTTP thread,
 * which never opens a file a request names (the worker reads it, and the job
 * fails with the reason if the file is bad) nor builds a mesh (a box domain's
 * tets are counted, not made). */
#ifndef PK_CHECK_CTX_H
#define PK_CHECK_CTX_H

typedef struct pk_check_ctx {
    int service; /* 1: a request to the daemon: open no input file, build no mesh */
} pk_check_ctx;

#endif
