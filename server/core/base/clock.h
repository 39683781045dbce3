/* A monotonic clock for the timings core reports (solve_ms, per-stage seconds). */
#ifndef AG_CLOCK_H
#define AG_CLOCK_H

/* Milliseconds since an arbitrary fixed point; only differences mean anything. */
double ag_clock_ms(void);
/* The same in seconds. */
double ag_clock_seconds(void);
/* Processor seconds this thread has used (per-stage figures on a shared machine). */
double ag_clock_thread_cpu_seconds(void);

#endif
