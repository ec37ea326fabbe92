/* What waking a sleeping process costs on this machine, without iceoryx2: the waker's time
 * for FUTEX_WAKE on a shared word (a peer blocked in FUTEX_WAIT) and for a datagram send on a
 * unix socket pair (a peer blocked in recv), once per millisecond as the CNC tick does.
 * The figure to compare with the "tick-done event" part of `cnc run`'s report.
 * Build and run: gcc -O2 tools/wake_cost.c -o /tmp/wake_cost && /tmp/wake_cost */
#define _GNU_SOURCE
#include <linux/futex.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

enum { ROUNDS = 3000 };

static long futex(atomic_uint *word, int op, unsigned value) {
    return syscall(SYS_futex, word, op, value, NULL, NULL, 0);
}

static uint64_t now_ns(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (uint64_t)t.tv_sec * 1000000000u + (uint64_t)t.tv_nsec;
}

static int by_value(const void *a, const void *b) {
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

static void report(const char *what, uint64_t *ns) {
    qsort(ns, ROUNDS, sizeof *ns, by_value);
    printf("%-28s p50 %6llu ns  p99 %6llu ns\n", what, (unsigned long long)ns[ROUNDS / 2],
           (unsigned long long)ns[ROUNDS * 99 / 100]);
}

static void pause_1ms(void) {
    struct timespec one = {0, 1000000};
    nanosleep(&one, NULL);
}

int main(void) {
    atomic_uint *word = mmap(NULL, 4096, PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
    int pair[2];
    uint64_t *ns = malloc(ROUNDS * sizeof *ns);
    if (word == MAP_FAILED || !ns || socketpair(AF_UNIX, SOCK_DGRAM, 0, pair) != 0) return 1;
    pid_t peer = fork();
    if (peer == 0) {
        unsigned seen = 0;
        for (int i = 0; i < ROUNDS; i++) {
            while (atomic_load(word) == seen) futex(word, FUTEX_WAIT, seen);
            seen = atomic_load(word);
        }
        char byte;
        for (int i = 0; i < ROUNDS; i++) recv(pair[1], &byte, 1, 0);
        _exit(0);
    }
    for (int i = 0; i < ROUNDS; i++) {
        pause_1ms();
        uint64_t t0 = now_ns();
        atomic_fetch_add(word, 1);
        futex(word, FUTEX_WAKE, 1);
        ns[i] = now_ns() - t0;
    }
    report("futex wake (peer waiting)", ns);
    for (int i = 0; i < ROUNDS; i++) {
        pause_1ms();
        uint64_t t0 = now_ns();
        send(pair[0], "x", 1, 0);
        ns[i] = now_ns() - t0;
    }
    report("datagram send (peer in recv)", ns);
    waitpid(peer, NULL, 0);
    return 0;
}
