// Directional albedo of Adobe's OpenPBR BSDF (github.com/adobe/openpbr-bsdf), for
// lookdev's check of its own OpenPBR model against an implementation it did not write.
//
// Built by lookdev.pipeline.analysis.openpbr_reference against a checkout of that
// repository and GLM:  g++ -O2 -std=c++17 -I<openpbr-bsdf> albedo.cpp -o albedo
//
// stdin: one material per line, "name key=value key=value ..." (colours as r,g,b);
// stdout: per material and view angle, "name angle R_r R_g R_b T_r T_g T_b": the mean
// sampled weight of directions above (R) and below (T) the surface, N samples per angle.
#include <glm/glm.hpp>
#include "openpbr.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <random>
#include <sstream>
#include <string>

static vec3 colour(const std::string& v)
{
    float r = 0, g = 0, b = 0;
    std::sscanf(v.c_str(), "%f,%f,%f", &r, &g, &b);
    return vec3(r, g, b);
}

static void set(OpenPBR_ResolvedInputs& in, const std::string& k, const std::string& v)
{
    const float f = std::strtof(v.c_str(), nullptr);
#define F(name) if (k == #name) { in.name = f; return; }
#define C(name) if (k == #name) { in.name = colour(v); return; }
    F(base_weight) C(base_color) F(base_diffuse_roughness) F(base_metalness)
    F(subsurface_weight) C(subsurface_color) F(subsurface_radius) C(subsurface_radius_scale)
    F(subsurface_scatter_anisotropy)
    F(specular_weight) C(specular_color) F(specular_roughness) F(specular_roughness_anisotropy)
    F(specular_ior)
    F(coat_weight) C(coat_color) F(coat_roughness) F(coat_roughness_anisotropy) F(coat_ior)
    F(coat_darkening)
    F(fuzz_weight) C(fuzz_color) F(fuzz_roughness)
    F(transmission_weight) C(transmission_color) F(transmission_depth) C(transmission_scatter)
    F(transmission_scatter_anisotropy) F(transmission_dispersion_scale)
    F(transmission_dispersion_abbe_number)
    F(thin_film_weight) F(thin_film_thickness) F(thin_film_ior)
    F(emission_luminance) C(emission_color) F(geometry_opacity)
    if (k == "geometry_thin_walled") { in.geometry_thin_walled = f != 0.0f; return; }
#undef F
#undef C
    std::cerr << "unknown input " << k << "\n";
    std::exit(2);
}

int main(int argc, char** argv)
{
    const int n = argc > 1 ? std::atoi(argv[1]) : 65536;
    const float angles[] = {0.0f, 30.0f, 45.0f, 60.0f, 75.0f, 85.0f};
    std::string line;
    while (std::getline(std::cin, line))
    {
        std::istringstream words(line);
        std::string name, word;
        words >> name;
        OpenPBR_ResolvedInputs in = openpbr_make_default_resolved_inputs();
        while (words >> word)
        {
            const auto eq = word.find('=');
            set(in, word.substr(0, eq), word.substr(eq + 1));
        }
        std::mt19937 rng(7);
        std::uniform_real_distribution<float> uni(0.0f, 1.0f);
        for (float deg : angles)
        {
            const float t = deg * 3.14159265358979f / 180.0f;
            const vec3 view = vec3(std::sin(t), 0.0f, std::cos(t));
            const OpenPBR_PreparedBsdf prepared = openpbr_prepare(
                in, vec3(1.0f), OpenPBR_BaseRgbWavelengths_nm, OpenPBR_VacuumIor, view);
            double r[3] = {0, 0, 0}, tr[3] = {0, 0, 0};
            for (int i = 0; i < n; ++i)
            {
                vec3 light;
                OpenPBR_DiffuseSpecular weight;
                float pdf;
                OpenPBR_BsdfLobeType type;
                openpbr_sample(prepared, vec3(uni(rng), uni(rng), uni(rng)), light, weight, pdf, type);
                if (!(pdf > 0.0f))
                    continue;
                const vec3 w = openpbr_get_sum_of_diffuse_specular(weight);
                if (!std::isfinite(w.x + w.y + w.z))
                    continue;
                double* acc = light.z >= 0.0f ? r : tr;
                acc[0] += w.x;
                acc[1] += w.y;
                acc[2] += w.z;
            }
            std::printf("%s %g %.6f %.6f %.6f %.6f %.6f %.6f\n", name.c_str(), deg, r[0] / n,
                        r[1] / n, r[2] / n, tr[0] / n, tr[1] / n, tr[2] / n);
        }
    }
    return 0;
}
