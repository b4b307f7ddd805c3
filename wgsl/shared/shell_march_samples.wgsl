// ShellMarch's samples (included by march_shell.wgsl): empty-space runs, trilinear filtering and
// lighting as the Reference does them, and compositing the held intervals nearest first.

// The occupancy pyramid a sample at MIP level `level` skips by: 0 (the texel's own) at level 0,
// else the coarser level c it mixes, whose pyramid holds the opacity dilated in s and t by as far
// as its voxels reach (twin: filter::pyramid).
fn filter_pyramid(level: f32, levels: u32) -> u32 {
    if (level <= 0.0) {
        return 0u;
    }
    return min(u32(floor(level)) + 1u, levels - 1u);
}

// How many samples of an interval in `prism` (of `object`) from map value c on are empty for
// certain (at most `most`): along the line c + k dc, until it leaves the largest brick around c
// that holds no opacity (in the object's occupancy pyramid `pyramid`, `words` words each).
fn empty_run(prism: ReferencePrism, object: ReferenceObject, c: vec4<f32>, dc: vec4<f32>, most: u32, pyramid: u32, words: u32) -> u32 {
    let res = object.resolution.xyz;
    let resf = vec3<f32>(res);
    let st = c.x * prism.uv01.xy + c.y * prism.uv01.zw + c.z * prism.uv2.xy;
    let x = vec3<f32>(fract(st), c.w) * resf;
    let dx = vec3<f32>(dc.x * prism.uv01.xy + dc.y * prism.uv01.zw + dc.z * prism.uv2.xy, dc.w) * resf;
    var run = 0.0;
    var offset = object.atlas.w + pyramid * words;
    for (var level = 0u; level < 3u; level++) {
        // Bricks of 4, 16, 64 voxels: shifts, as vector integer division is slow on llvmpipe.
        let shift = 2u + 2u * level;
        let size = 1u << shift;
        let dims = (res + vec3<u32>(size - 1u)) >> vec3<u32>(shift);
        let brick = vec3<u32>(clamp(floor(x / f32(size)), vec3<f32>(0.0), vec3<f32>(dims - vec3<u32>(1u))));
        if (shell_occupancy[offset + (brick.z * dims.y + brick.y) * dims.x + brick.x] != 0u) {
            break;
        }
        // The brick and half a voxel around it (the occupancy covers the filter's reach from
        // there); along w the first and last bricks reach on (sampling clamps there).
        var lo = vec3<f32>(brick * size) - 0.5;
        var hi = vec3<f32>(min((brick + 1u) * size, res)) + 0.5;
        lo.z = select(lo.z, -FAR, brick.z == 0u);
        hi.z = select(hi.z, FAR, brick.z + 1u == dims.z);
        let exit = select(select((lo - x) / dx, (hi - x) / dx, dx > vec3<f32>(0.0)), vec3<f32>(FAR), dx == vec3<f32>(0.0));
        run = floor(min(min(exit.x, exit.y), exit.z)) + 1.0;
        offset += dims.x * dims.y * dims.z;
    }
    return u32(clamp(run, 0.0, f32(most)));
}


struct Axis {
    i0: u32,
    i1: u32,
    f: f32,
}

// c in [0, 1] (s and t after `fract`, w clamped): the voxels either side are in [-1, n], so
// wrapping needs no modulo (a vector modulo is slow on llvmpipe).
fn axis(c: f32, n: u32, wrap: bool) -> Axis {
    let x = c * f32(n) - 0.5;
    let fl = floor(x);
    let m = i32(n);
    var i0 = i32(fl);
    var i1 = i0 + 1;
    if (wrap) {
        i0 = select(i0, i0 + m, i0 < 0);
        i1 = select(i1, i1 - m, i1 >= m);
    } else {
        i0 = clamp(i0, 0, m - 1);
        i1 = clamp(i1, 0, m - 1);
    }
    return Axis(u32(i0), u32(i1), x - fl);
}

// Corner k (bit 0: x, bit 1: y, bit 2: z) of a trilinear sample between voxels `ax`, `ay`, `az`:
// its voxel and its weight.
struct Corner {
    x: u32,
    y: u32,
    z: u32,
    weight: f32,
}

fn corner(ax: Axis, ay: Axis, az: Axis, k: u32) -> Corner {
    let x = select(ax.i0, ax.i1, (k & 1u) != 0u);
    let y = select(ay.i0, ay.i1, (k & 2u) != 0u);
    let z = select(az.i0, az.i1, (k & 4u) != 0u);
    let weight = select(1.0 - ax.f, ax.f, (k & 1u) != 0u) * select(1.0 - ay.f, ay.f, (k & 2u) != 0u)
        * select(1.0 - az.f, az.f, (k & 4u) != 0u);
    return Corner(x, y, z, weight);
}

// The f16 in the low 16 bits of h, exactly (`unpack2x16float` needs a capability that Mesa's
// Vulkan drivers lack without f16 support). The levels hold no infinity or NaN.
fn half(h: u32) -> f32 {
    let e = (h >> 10u) & 0x1fu;
    let m = h & 0x3ffu;
    // Subnormal: m 2^-24; normal: the exponent rebiased from 15 to 127.
    let v = select(bitcast<f32>(((e + 112u) << 23u) | (m << 13u)), f32(m) * 5.9604645e-8, e == 0u);
    return select(v, -v, (h & 0x8000u) != 0u);
}

fn half4(v: vec2<u32>) -> vec4<f32> {
    return vec4<f32>(half(v.x & 0xffffu), half(v.x >> 16u), half(v.y & 0xffffu), half(v.y >> 16u));
}

// Trilinear filtering as the volume sampler does it (the Reference's atlas), at MIP level l of
// `object`'s texel (or of its normals): repeat in s and t, clamp in w. Level 0 is the atlas
// (8 bits); a level l >= 1 of the footprint filter halves s and t and starts at `start` in
// `shell_mips` (f16, rows padded to 32 voxels).
fn sample_volume(object: ReferenceObject, l: u32, start: u32, uvw: vec3<f32>, normals: bool) -> vec4<f32> {
    let n = object.resolution.xy >> vec2<u32>(l);
    let ax = axis(fract(uvw.x), n.x, true);
    let ay = axis(fract(uvw.y), n.y, true);
    let az = axis(uvw.z, object.resolution.z, false);
    let atlas = l == 0u;
    let offset = select(start, select(object.atlas.x, object.atlas.z, normals), atlas);
    let pitch = select((n.x + 31u) & ~31u, object.atlas.y, atlas);
    var out = vec4<f32>(0.0);
    for (var k = 0u; k < 8u; k++) {
        let c = corner(ax, ay, az, k);
        let at = offset + (c.z * n.y + c.y) * pitch + c.x;
        if (atlas) {
            if (normals) {
                out += unpack4x8snorm(normal_atlas[at]) * c.weight;
            } else {
                out += unpack4x8unorm(texel_atlas[at]) * c.weight;
            }
        } else if (normals) {
            out += half4(shell_normal_mips[at]) * c.weight;
        } else {
            out += half4(shell_mips[at]) * c.weight;
        }
    }
    return out;
}

// Where the two MIP levels the current run's samples mix start in `shell_mips` (and
// `shell_normal_mips`): found once per run, so that a sample runs no loop of variable length
// (lavapipe's loop limit counts every iteration of every loop of an invocation).
var<private> mip_starts: vec2<u32>;

// Where level l >= 1 of `object`'s texel starts in `shell_mips`.
fn level_start(object: ReferenceObject, footprint: ShellFilter, l: u32) -> u32 {
    var offset = footprint.mips;
    for (var k = 1u; k < l; k++) {
        let n = object.resolution.xy >> vec2<u32>(k);
        offset += ((n.x + 31u) & ~31u) * n.y * object.resolution.z;
    }
    return offset;
}

// The texel (or its normals) at fractional MIP level `level` (0: level 0 alone): the two levels
// around it mixed. Without `filtering` only the first call is compiled: llvmpipe inlines every
// call of the tap loop, and the filter's two more made the kernel about 10% slower.
fn sample_filtered(object: ReferenceObject, uvw: vec3<f32>, level: f32, normals: bool) -> vec4<f32> {
    if (!filtering || level <= 0.0) {
        return sample_volume(object, 0u, 0u, uvw, normals);
    }
    let l0 = u32(floor(level));
    let f = level - floor(level);
    let a = sample_volume(object, l0, mip_starts.x, uvw, normals);
    if (f == 0.0) {
        return a;
    }
    return mix(a, sample_volume(object, l0 + 1u, mip_starts.y, uvw, normals), f);
}

// Per-pixel lighting as the Reference does it (shared/shading.wgsl), at map value c, the normals
// read at MIP level `level`.
fn shade(index: u32, object: ReferenceObject, c: vec4<f32>, uvw: vec3<f32>, albedo: vec3<f32>, level: f32) -> vec3<f32> {
    let shape = load_shape(index);
    let fa = vertex_frames[shape.ids[0]];
    let fb = vertex_frames[shape.ids[1]];
    let fc = vertex_frames[shape.ids[2]];
    let ds = c.x * fa.ds.xyz + c.y * fb.ds.xyz + c.z * fc.ds.xyz;
    let dt = c.x * fa.dt.xyz + c.y * fb.dt.xyz + c.z * fc.dt.xyz;
    let dw = c.x * (shape.top[0] - shape.bottom[0]) + c.y * (shape.top[1] - shape.bottom[1]) + c.z * (shape.top[2] - shape.bottom[2]);
    let sign_j = select(-1.0, 1.0, dot(ds, cross(dt, dw)) >= 0.0);
    let tn = sample_filtered(object, uvw, level, true).xyz;
    var n = cross(dt, dw) * sign_j * tn.x + cross(dw, ds) * sign_j * tn.y + cross(ds, dt) * sign_j * tn.z;
    n = select(-ray, normalize(n), dot(n, n) > 1e-20);
    return shade_phong(albedo, n, frame.light_dir, -ray, PIXEL_SPECULAR, PIXEL_SHININESS);
}

// Composites one sample, h apart from the next, of an interval in prism `index` (`prism`, of
// `object`) at ray distance t and map value c (w < 0: none), read at MIP level `level`.
fn composite(index: u32, prism: ReferencePrism, object: ReferenceObject, h: f32, t: f32, c: vec4<f32>, level: f32) {
    taken += 1u;
    if (c.w < 0.0) {
        return;
    }
    let uvw = vec3<f32>(c.x * prism.uv01.xy + c.y * prism.uv01.zw + c.z * prism.uv2.xy, c.w);
    let texel = sample_filtered(object, uvw, level, false);
    if (texel.a >= OPAQUE_ALPHA && !opaque_found) {
        opaque_found = true;
        record_opaque_depth(pixel, t * dot(ray, frame.forward.xyz));
    }
    let alpha = clamp(texel.a, 0.0, MAX_ALPHA);
    if (alpha > 1e-6) {
        var colour = texel.rgb / alpha;
        if ((object.resolution.w & 1u) != 0u) {
            colour = shade(index, object, c, uvw, colour, level);
        }
        // The step-corrected opacity: 1 - (1 - a)^(h / opacity_length).
        let a = 1.0 - exp(log(1.0 - alpha) * h / object.params.x);
        rgb += colour * a * transmittance;
        transmittance *= 1.0 - a;
    }
}

// The index of the first sample of interval s at or after `bound` (its samples from k on).
fn first_at(s: u32, k: u32, bound: f32) -> u32 {
    let t0 = iv_t0[s];
    let h = iv_h[s];
    let n = iv_n[s];
    var e = u32(clamp(ceil((bound - t0) / h - 0.5), f32(k), f32(n)));
    while (e > k && t0 + (f32(e - 1u) + 0.5) * h >= bound) {
        e -= 1u;
    }
    while (e < n && t0 + (f32(e) + 0.5) * h < bound) {
        e += 1u;
    }
    return e;
}

// Samples of interval s before `limit` (its next one in any case: it is the nearest held), in
// order, until the budget or the ray runs out. The interval's state is kept in registers meanwhile:
// on llvmpipe every read of a dynamically indexed private array is a chain of selects over all of
// its entries, so the loop reads none but where a piece ends.
fn run(s: u32, limit: f32) {
    let index = iv_prism[s];
    let prism = shell_prisms[index];
    let object = shell_objects[prism.vertices.w];
    let t0 = iv_t0[s];
    let h = iv_h[s];
    let n = iv_n[s];
    let m = iv_pieces[s];
    let level = iv_level[s];
    let footprint = shell_filters[prism.vertices.w];
    let pyramid = filter_pyramid(level, footprint.levels);
    if (filtering && level > 0.0) {
        let l0 = u32(floor(level));
        mip_starts = vec2<u32>(level_start(object, footprint, l0), level_start(object, footprint, l0 + 1u));
    }
    var piece = iv_piece[s];
    var k = iv_k[s];
    var t = iv_next[s];
    var exact = iv_exact[s];
    var ta = iv_ta[s];
    var tb = iv_tb[s];
    var ca = iv_ca[s];
    var cb = iv_cb[s];
    // Skips stay in the current piece and before `limit`: they end at the first sample at or
    // after either (found again when the piece changes).
    var end = first_at(s, k, select(min(tb, limit), limit, piece + 1u >= m));
    var first = true;
    while ((first || t < limit) && budget > 0 && transmittance >= min_transmittance) {
        first = false;
        if (t >= tb && piece + 1u < m) {
            while (t >= iv_tb[s] && iv_piece[s] + 1u < m) {
                set_piece(s, iv_piece[s] + 1u, vec4<f32>(0.0), true);
            }
            piece = iv_piece[s];
            exact = iv_exact[s];
            ta = iv_ta[s];
            tb = iv_tb[s];
            ca = iv_ca[s];
            cb = iv_cb[s];
            end = first_at(s, k, select(min(tb, limit), limit, piece + 1u >= m));
        }
        budget -= 1;
        var c: vec4<f32>;
        var dc = vec4<f32>(0.0);
        var most = 1u;
        if (exact) {
            var shape = load_shape(index);
            c = prism_inverse(ray * t, &shape);
            budget -= EXACT_COST;
        } else {
            c = mix(ca, cb, (t - ta) / (tb - ta));
            dc = (cb - ca) * (h / (tb - ta));
            most = end - k;
        }
        var step = 1u;
        let jump = select(0u, empty_run(prism, object, c, dc, most, pyramid, footprint.occupancy), shell_params.counts.w != 0u && c.w >= 0.0);
        if (jump > 0u) {
            skipped += jump;
            step = jump;
        } else {
            composite(index, prism, object, h, t, c, level);
        }
        k += step;
        t = select(FAR, t0 + (f32(k) + 0.5) * h, k < n);
    }
    iv_k[s] = k;
    iv_next[s] = t;
}

// Composites every held sample before `end`, nearest first across intervals.
fn march_to(end: f32) {
    loop {
        budget -= 1;
        var best = MAX_ACTIVE;
        var t_best = end;
        var t_second = end;
        var i = 0u;
        while (i < held) {
            let t = iv_next[i];
            if (t >= FAR || t >= t_opaque) {
                // Done: the last held interval takes its slot.
                held -= 1u;
                copy_interval(held, i);
                continue;
            }
            if (t < t_best) {
                t_second = t_best;
                t_best = t;
                best = i;
            } else if (t < t_second) {
                t_second = t;
            }
            i += 1u;
        }
        if (best == MAX_ACTIVE || budget <= 0 || transmittance < min_transmittance) {
            return;
        }
        run(best, t_second);
    }
}

fn copy_interval(src: u32, dst: u32) {
    iv_prism[dst] = iv_prism[src];
    iv_t0[dst] = iv_t0[src];
    iv_t1[dst] = iv_t1[src];
    iv_h[dst] = iv_h[src];
    iv_n[dst] = iv_n[src];
    iv_k[dst] = iv_k[src];
    iv_next[dst] = iv_next[src];
    iv_pieces[dst] = iv_pieces[src];
    iv_piece[dst] = iv_piece[src];
    iv_exact[dst] = iv_exact[src];
    iv_ta[dst] = iv_ta[src];
    iv_tb[dst] = iv_tb[src];
    iv_ca[dst] = iv_ca[src];
    iv_cb[dst] = iv_cb[src];
    iv_c1[dst] = iv_c1[src];
    iv_level[dst] = iv_level[src];
}

fn next_held() -> f32 {
    var t = FAR;
    for (var i = 0u; i < held; i++) {
        t = min(t, iv_next[i]);
    }
    return t;
}
