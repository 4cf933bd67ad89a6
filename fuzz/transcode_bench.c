/* Runs one program of programs.h (tools/native_fuzz_programs.py) on one payload, many times:
 * a driver to count the transcoder's instructions per message, e.g.
 *
 *   valgrind --tool=callgrind --toggle-collect=rgb_to_cdr \
 *       transcode_bench 'nav_msgs/msg/Odometry <- gz.msgs.Odometry' payload.bin 1000
 *
 * (callgrind's total over 1000 calls, divided by 1000). Built like the extension (-O2). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "programs.h"
#include "transcode.h"

int main(int argc, char **argv) {
    if (argc != 4) {
        fprintf(stderr, "usage: %s PROGRAM-NAME PAYLOAD-FILE COUNT\n", argv[0]);
        return 2;
    }
    const struct fuzz_program *chosen = NULL;
    for (size_t i = 0; i < PROGRAM_COUNT; i++)
        if (strcmp(PROGRAMS[i].name, argv[1]) == 0) chosen = &PROGRAMS[i];
    FILE *file = fopen(argv[2], "rb");
    if (chosen == NULL || file == NULL) {
        fprintf(stderr, "no program %s or no file %s\n", argv[1], argv[2]);
        return 2;
    }
    static uint8_t payload[1 << 20];
    size_t n = fread(payload, 1, sizeof payload, file);
    fclose(file);
    struct rgb_program program;
    const char *why = "";
    if (rgb_load(&program, chosen->schema, chosen->schema_len, chosen->ops, chosen->ops_len, &why)) {
        fprintf(stderr, "not loaded: %s\n", why);
        return 1;
    }
    struct rgb_out out = {0};
    long count = atol(argv[3]);
    enum rgb_status status = RGB_OK;
    for (long k = 0; k < count; k++) status = rgb_to_cdr(&program, payload, n, &out, NULL);
    printf("status %d, %zu payload bytes, %zu CDR bytes\n", (int)status, n, out.len);
    rgb_out_free(&out);
    return 0;
}
