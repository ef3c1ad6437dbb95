//! Criterion benchmarks of the kernel (hold model through the engine vs a
//! bare BinaryHeap loop) and of the frame pipeline at both fidelities. The
//! same measurements, with ratios printed, are `rendersim bench`.

use criterion::{Criterion, criterion_group, criterion_main};

fn kernel(c: &mut Criterion) {
    let mut g = c.benchmark_group("hold_model_1k_pending_1M_events");
    g.sample_size(10);
    g.bench_function("engine_and_bare_heap", |b| {
        b.iter(|| std::hint::black_box(rendersim::bench::kernel(1_000, 1_000_000)))
    });
    g.finish();
    let k = rendersim::bench::kernel_case(rendersim::bench::KernelWork::Hold, 1_000, 2_000_000, 5);
    println!(
        "hold model, median (min-max) of 5: engine {}, bare heap {}, ratio {}",
        k.engine_events_per_s.show(1e-6, 2, " M events/s"),
        k.bare_events_per_s.show(1e-6, 2, " M events/s"),
        k.ratio.show(1.0, 3, "")
    );
}

fn pipeline(c: &mut Criterion) {
    let mut g = c.benchmark_group("one_frame_grid_200x200");
    g.sample_size(10);
    g.bench_function("triangle_and_draw_fidelity", |b| {
        b.iter(|| std::hint::black_box(rendersim::bench::pipeline(200, 1).unwrap()))
    });
    g.finish();
}

criterion_group!(benches, kernel, pipeline);
criterion_main!(benches);
