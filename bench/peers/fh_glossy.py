"""fredholm's glossy material (kernels/bsdf.h, illum 2 with Ks > 0) as a Mitsuba 3 BSDF, so
that Mitsuba renders the same model where its own plugins differ (roughplastic's coating
weighs the diffuse part differently, and its Smith term is separable): Lambert Kd scaled by
1 - max F(wo), plus GGX reflection with Schlick's Fresnel (F0 = Ks) and the
height-correlated Smith term; the lobe chosen with fredholm's p_specular, the GGX direction
by its visible normals. Written in Dr.Jit operations, so the JIT variants compile it into
their kernels like a built-in plugin.

Mitsuba's names are the reverse of fredholm's: its si.wi is the direction to the viewer
(fredholm's wo) and its wo the direction light arrives from (fredholm's wi); its eval
includes the cosine at wo.

  register(mi, dr) makes the plugin "fh_glossy" (properties alpha, kd_r, kd_g, kd_b, ks_r,
  ks_g, ks_b); load it one-sided and wrap it in "twosided", as fredholm shades both sides.
"""


def register(mi, dr):
    def luminance(c):
        return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]

    class FredholmGlossy(mi.BSDF):
        def __init__(self, props):
            mi.BSDF.__init__(self, props)
            self.alpha = props.get("alpha", 0.1)
            kd = [props.get("kd_" + c, 0.0) for c in "rgb"]
            ks = [props.get("ks_" + c, 0.0) for c in "rgb"]
            self.kd, self.ks, self.ks_max = mi.Color3f(*kd), mi.Color3f(*ks), max(ks)
            specular, diffuse = luminance(ks), luminance(kd) * (1.0 - max(ks))
            self.p_specular = specular / (specular + diffuse) if specular + diffuse > 0 else 0.0
            reflection = mi.BSDFFlags.GlossyReflection | mi.BSDFFlags.FrontSide
            self.m_components = [mi.BSDFFlags.DiffuseReflection | mi.BSDFFlags.FrontSide, reflection]
            self.m_flags = self.m_components[0] | self.m_components[1]

        def schlick(self, cos_theta):
            m = 1.0 - dr.clip(cos_theta, 0.0, 1.0)
            return self.ks + (1.0 - self.ks) * (m * m * m * m * m)

        def ggx_d(self, h):
            a2 = self.alpha * self.alpha
            t = h.z * h.z * (a2 - 1.0) + 1.0
            return a2 / (dr.pi * t * t)

        def ggx_lambda(self, w):
            c2 = w.z * w.z
            t2 = dr.maximum(1.0 - c2, 0.0) / c2
            return dr.select(c2 <= 0.0, 0.0, 0.5 * (dr.sqrt(1.0 + self.alpha * self.alpha * t2) - 1.0))

        def value_and_pdf(self, v, l):
            """f(v, l) cos(l) and the density of sampling l from v."""
            up = (v.z > 0.0) & (l.z > 0.0)
            f = self.schlick(v.z)
            diffuse = self.kd * (dr.inv_pi * (1.0 - dr.maximum(dr.maximum(f.x, f.y), f.z)))
            h = dr.normalize(v + l)
            d = self.ggx_d(h)
            lambda_v, lambda_l = self.ggx_lambda(v), self.ggx_lambda(l)
            glossy = self.schlick(dr.dot(v, h)) * (d / ((1.0 + lambda_v + lambda_l) * 4.0 * v.z * l.z))
            value = dr.select(up, (diffuse + glossy) * l.z, 0.0)
            pdf = (1.0 - self.p_specular) * l.z * dr.inv_pi + self.p_specular * d / ((1.0 + lambda_v) * 4.0 * v.z)
            return value, dr.select(up, pdf, 0.0)

        def sample(self, ctx, si, sample1, sample2, active):
            v = si.wi
            glossy = sample1 < self.p_specular
            distribution = mi.MicrofacetDistribution(mi.MicrofacetType.GGX, self.alpha, True)
            h, _ = distribution.sample(v, sample2)
            l = dr.select(glossy, mi.reflect(v, h), mi.warp.square_to_cosine_hemisphere(sample2))
            value, pdf = self.value_and_pdf(v, l)
            bs = mi.BSDFSample3f()
            bs.wo, bs.pdf, bs.eta = l, pdf, 1.0
            bs.sampled_type = dr.select(glossy, mi.UInt32(int(mi.BSDFFlags.GlossyReflection)),
                                        mi.UInt32(int(mi.BSDFFlags.DiffuseReflection)))
            bs.sampled_component = dr.select(glossy, mi.UInt32(1), mi.UInt32(0))
            ok = active & (pdf > 0.0)
            return bs, dr.select(ok, value / pdf, 0.0)

        def eval(self, ctx, si, wo, active):
            return self.value_and_pdf(si.wi, wo)[0]

        def pdf(self, ctx, si, wo, active):
            return self.value_and_pdf(si.wi, wo)[1]

        def eval_pdf(self, ctx, si, wo, active):
            return self.value_and_pdf(si.wi, wo)

        def traverse(self, callback):
            pass

        def to_string(self):
            return "FredholmGlossy[alpha=%g]" % self.alpha

    mi.register_bsdf("fh_glossy", lambda props: FredholmGlossy(props))
