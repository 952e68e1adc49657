/* test_job_files.c — daemon/store/job_files.c: a job directory's paths, the
 * names the service's documents and tests rely on, and truncation refused. */
#include <string.h>

#include "check.h"
#include "daemon/store/job_files.h"

static void test_paths(void)
{
    char dir[64], path[80];
    CHECK(pk_job_dir("/srv/packd", "f47ac10b-58cc-4372-a567-0e02b2c3d479", dir, sizeof dir) == 0);
    CHECK(!strcmp(dir, "/srv/packd/jobs/f47ac10b-58cc-4372-a567-0e02b2c3d479"));
    CHECK(pk_job_file_path(dir, PK_JOB_RESULT, path, sizeof path) == 0);
    CHECK(!strcmp(path, "/srv/packd/jobs/f47ac10b-58cc-4372-a567-0e02b2c3d479/result.h5"));
    CHECK(pk_job_dir("/srv/packd", "f47ac10b-58cc-4372-a567-0e02b2c3d479", dir, 20) == -1);
    CHECK(pk_job_file_path("/a/very/long/directory", PK_JOB_CHECKPOINT, path, 24) == -1);
}

static void test_names_distinct(void)
{
    static const pk_job_file all[] = {PK_JOB_INPUT, PK_JOB_RESULT, PK_JOB_XDMF,      PK_JOB_SUMMARY,
                                      PK_JOB_LOG,   PK_JOB_LOCK,   PK_JOB_CHECKPOINT};
    size_t n = sizeof all / sizeof *all;
    for (size_t i = 0; i < n; i++) {
        CHECK(strlen(pk_job_file_name(all[i])) > 0 && !strchr(pk_job_file_name(all[i]), '/'));
        /* no name holds ".tmp": the executor removes those as leftovers */
        CHECK(!strstr(pk_job_file_name(all[i]), ".tmp"));
        for (size_t j = 0; j < i; j++)
            CHECK(strcmp(pk_job_file_name(all[i]), pk_job_file_name(all[j])) != 0);
    }
    CHECK(!strcmp(pk_job_file_name(PK_JOB_INPUT), "job.json"));
    CHECK(!strcmp(pk_job_file_name(PK_JOB_CHECKPOINT), "checkpoint.h5"));
}

int main(void)
{
    RUN(test_paths);
    RUN(test_names_distinct);
    return check_summary();
}
