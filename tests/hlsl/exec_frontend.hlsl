// Run on the driver by tests/hlsl_exec.rs: default arguments, templates,
// classes with static and out-of-line methods, inheritance, static members,
// operator[], sizeof, functional casts, buffers passed to functions; static
// locals initialized on first use, methods of constant buffers, `S::m()`
// inside `S`, methods returning a buffer, overloaded function templates.
RWStructuredBuffer<float> results : register(u0);

struct Sky
{
    float3 color;
    float intensity;
    float total() { return color.x + color.y + color.z; }
};
ConstantBuffer<Sky> sky : register(b1);

float brightness(Sky s) { return (s.color.x + s.color.y + s.color.z) * s.intensity; }

namespace shading
{
    float fresnel(float f0) { return f0 + 0.5; }
    namespace specular
    {
        // `fresnel` is found in the enclosing namespace.
        float reflect(float f0) { return fresnel(f0) * 2; }
    }
}

// A user template named like an intrinsic does not hide it.
template<typename T>
T TraceRay(T x) { return x * 3; }

float scaled(float x, uint scale = 3, float bias = 0.5) { return x * scale + bias; }

template<typename T>
T twice(T v) { return v + v; }

template<uint N>
float sumTo() { float s = 0; for (uint i = 1; i <= N; i++) s += i; return s; }

template<typename T>
struct Pair
{
    T a;
    T b;
    T sum() { return a + b; }
};

class Counter
{
public:
    uint n;
    void add(uint by = 1);
    uint get() { return n; }
    // A method named with its struct, as C++ allows.
    uint twice() { return Counter::get() * 2; }
    static Counter make(uint start) { Counter c; c.n = start; return c; }
};

void Counter::add(uint by) { n += by; }

struct Base
{
    float x;
    float doubled() { return x * 2; }
};

struct Derived : Base
{
    float y;
};

struct Table
{
    static const uint Size = 4;
    float v[Size];
    float operator[](uint i) { return v[i % Size]; }
};

struct Packed
{
    float4 data;
};

float first(RWStructuredBuffer<float> buf) { return buf[0]; }

// A method returning a buffer is inlined where it is called.
struct Output
{
    uint base;
    RWStructuredBuffer<float> buffer() { return results; }
    float peek() { RWStructuredBuffer<float> b = buffer(); return b[base]; }
};

// Initialized when first reached: the second call keeps the first total.
float counted(float start)
{
    static float total = start * 2;
    total += 1;
    return total;
}

// Two templates whose instances share a name (`scaleBy<float>`).
template<typename T>
T scaleBy(T x, T k) { return x * k; }
template<typename T>
T scaleBy(T x) { return scaleBy(x, (T)3); }

void store(uint i, float v) { results[i] = v; }
// `return` of a void call in a void function.
void forward(uint i, float v) { return store(i, v); }

[numthreads(1, 1, 1)]
void Main()
{
    results[0] = scaled(2.0);                    // 6.5
    results[1] = scaled(2.0, 1);                 // 2.5
    results[2] = twice(1.25);                    // 2.5
    results[3] = twice(int2(3, 4)).y;            // 8
    results[4] = sumTo<4>();                     // 10
    Pair<float> p;
    p.a = 1.5;
    p.b = 2.0;
    results[5] = p.sum();                        // 3.5
    Counter c = Counter::make(5);
    c.add();
    c.add(10);
    results[6] = c.n;                            // 16
    Derived d;
    d.x = 3;
    d.y = 1;
    results[7] = d.doubled() + d.y;              // 7
    Table t;
    t.v[0] = 10; t.v[1] = 11; t.v[2] = 12; t.v[3] = 13;
    results[8] = t[6];                           // 12
    results[9] = sizeof(Derived) + sizeof(float3x4); // 8 + 48 = 56
    Packed k = Packed(float4(1, 2, 3, 4));
    results[10] = k.data.z;                      // 3
    results[11] = Table::Size;                   // 4
    results[12] = first(results) + 1;            // 7.5
    const uint N = 3;
    float local[N] = { 1, 2, 4 };
    results[13] = local[N - 1] + N;              // 7
    results[14] = shading::specular::reflect(1); // 3
    results[15] = TraceRay(1.5);                 // 4.5
    results[16] = brightness(sky);               // (1 + 2 + 3) * 0.5 = 3
    forward(17, 9.0);                            // 9
    results[18] = counted(1);                    // 1 * 2 + 1 = 3
    results[19] = counted(5);                    // 3 + 1 = 4
    results[20] = sky.total();                   // 6
    results[21] = c.twice();                     // 32
    Output o;
    o.base = 1;
    results[22] = o.peek();                      // results[1] = 2.5
    results[23] = scaleBy(2.0);                  // 6
}
