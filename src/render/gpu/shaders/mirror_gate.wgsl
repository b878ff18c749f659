// Between two bounces of the mirror pass: the next bounce's workgroups, written as indirect
// dispatch arguments, where `mirror_step` counted chains still live; none once every chain has
// ended, so a frame whose mirrors reflect once runs one bounce whatever the depth limit. The
// host prepends the counter slots (`MIRROR_LIVE_SLOT`, `MIRROR_BOUNCES_SLOT`).

@group(0) @binding(0) var<storage, read_write> counters: array<atomic<u32>>;
// x, y, z of the next dispatch, then the frame's full x and y.
@group(0) @binding(1) var<storage, read_write> args: array<u32, 5>;

@compute @workgroup_size(1)
fn mirror_gate() {
    let live = atomicExchange(&counters[MIRROR_LIVE_SLOT], 0u);
    if (live > 0u) {
        args[0] = args[3];
        args[1] = args[4];
        args[2] = 1u;
        atomicAdd(&counters[MIRROR_BOUNCES_SLOT], 1u);
    } else {
        args[0] = 0u;
        args[1] = 0u;
        args[2] = 0u;
    }
}
