#include "scene_panel.h"

#include "animation.h"

#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QScrollArea>
#include <QSignalBlocker>
#include <QVBoxLayout>

#include <algorithm>
#include <array>

namespace tyndall::studio {

namespace {

QDoubleSpinBox* spinBox(double value) {
    auto* spin = new QDoubleSpinBox;
    spin->setRange(-1e6, 1e6);
    spin->setDecimals(4);
    spin->setSingleStep(0.05);
    spin->setValue(value);
    spin->setKeyboardTracking(false);  // one edit per value typed, not per key
    // Its size hint fits the range's widest text ("-1000000.0000"): a vec3 row of three would need a horizontal scroll
    // bar in the dock's default width. It may shrink to what a value of this scene needs instead.
    spin->setMinimumWidth(64);
    return spin;
}

// A component of a vec3 row: without arrows, which would take a third of its width (the arrow keys, and the wheel
// once it has the focus, still step it).
QDoubleSpinBox* componentSpinBox(double value) {
    QDoubleSpinBox* spin = spinBox(value);
    spin->setButtonSymbols(QAbstractSpinBox::NoButtons);
    spin->setMinimumWidth(48);
    return spin;
}

// An integer field (a simulation's steps) shows no decimals and steps by one.
QDoubleSpinBox* integerSpinBox(double value) {
    QDoubleSpinBox* spin = spinBox(value);
    spin->setDecimals(0);
    spin->setSingleStep(1.0);
    return spin;
}

// A medium's phase function: its type, and the parameters that type uses (g of hg and mix, a of mix, b of eddington).
// A Legendre series is offered only to a medium that has one (its coefficients are edited in the file).
template <typename Field>
void addPhaseFields(std::vector<Field>& out, const nlohmann::json& medium, const std::string& prefix) {
    const nlohmann::json phase = medium.value("phase", nlohmann::json::object());
    const std::string type = phase.value("type", "isotropic");
    QStringList types = {"isotropic", "hg", "mix", "rayleigh", "eddington", "hazy-mie", "murky-mie"};
    if (type == "legendre") types << "legendre";
    out.push_back({"", "phase", prefix + "phase.type", type, types});
    const std::vector<std::pair<const char*, std::vector<std::string>>> uses = {
        {"g", {"hg", "mix"}}, {"a", {"mix"}}, {"b", {"eddington"}}};
    for (const auto& [key, types] : uses) {
        if (std::find(types.begin(), types.end(), type) == types.end()) continue;
        // A parameter the file leaves at its default is not written: the field shows the default.
        const double fallback = std::string(key) == "a" ? 1.0 : 0.0;
        out.push_back({"", QString("phase ") + key, prefix + "phase." + key, phase.value(key, fallback)});
    }
}

}  // namespace

ScenePanel::ScenePanel(Session& session, QWidget* parent) : QWidget(parent), session_(session) {
    auto* outer = new QVBoxLayout(this);
    auto* scroll = new QScrollArea;
    scroll->setWidgetResizable(true);
    auto* inner = new QWidget;
    form_ = new QFormLayout(inner);
    scroll->setWidget(inner);
    status_ = new QLabel;
    status_->setObjectName("sceneStatus");
    status_->setWordWrap(true);
    outer->addWidget(scroll, 1);
    outer->addWidget(status_);
    connect(&session_, &Session::projectReplaced, this, &ScenePanel::rebuild);
    connect(&session_, &Session::sceneChanged, this, [this] {
        if (!updating_) refresh();
    });
}

std::vector<ScenePanel::Field> ScenePanel::fields() const {
    std::vector<Field> out;
    if (session_.path().isEmpty()) return out;  // no project (an image-only session): no scene
    const nlohmann::json j = projectToJson(session_.project());
    out.push_back({"camera", "", "", {}});
    for (const char* key : {"position", "target", "fovY"})
        if (j["camera"].contains(key)) out.push_back({"", key, std::string("camera.") + key, j["camera"][key]});
    for (const char* group : {"media", "lights"}) {
        if (!j.contains(group)) continue;
        for (const auto& element : j[group]) {
            const std::string name = element.value("name", "");
            out.push_back({QString::fromStdString(std::string(group) + ": " + name), "", "", {}});
            const std::string prefix = std::string(group) + "[" + name + "].";
            for (const char* key : {"sigma_s", "sigma_a", "position", "direction", "intensity", "irradiance", "radiance"})
                if (element.contains(key)) out.push_back({"", key, prefix + key, element[key]});
            if (std::string(group) == "media") addPhaseFields(out, element, prefix);
        }
    }
    // Materials: the type, and the parameters it uses.
    if (j.contains("materials")) {
        for (const auto& element : j["materials"]) {
            const std::string name = element.value("name", "");
            out.push_back({QString::fromStdString("material: " + name), "", "", {}});
            const std::string prefix = "materials[" + name + "].";
            const std::string type = element.value("type", "diffuse");
            out.push_back({"", "type", prefix + "type", type, {"diffuse", "ggx"}});
            const std::vector<const char*> keys =
                type == "ggx" ? std::vector<const char*>{"f0", "alpha", "alphaX", "alphaY"} : std::vector<const char*>{"albedo"};
            for (const char* key : keys)
                if (element.contains(key)) out.push_back({"", key, prefix + key, element[key]});
        }
    }
    // Particle media: the extinction and, once it has one (Animation > Play or Step creates it), the simulation.
    if (j.contains("particleMedia")) {
        for (const auto& element : j["particleMedia"]) {
            const std::string name = element.value("name", "");
            out.push_back({QString::fromStdString("particle medium: " + name), "", "", {}});
            const std::string prefix = "particleMedia[" + name + "].";
            if (element.contains("extinction")) out.push_back({"", "extinction", prefix + "extinction", element["extinction"]});
            addPhaseFields(out, element, prefix);
            if (!element.contains("simulation")) continue;
            const nlohmann::json& sim = element["simulation"];
            for (const char* key : {"steps", "timeStep", "stiffness", "viscosity", "offset"})
                if (sim.contains(key)) out.push_back({"", key, prefix + "simulation." + key, sim[key]});
        }
    }
    return out;
}

void ScenePanel::refresh() {
    // The same rows: their values change in place (a field must not be deleted inside its own signal, as a refused
    // value typed into it would do). Other rows: rebuilt from the event loop.
    const std::vector<Field> now = fields();
    std::vector<std::string> paths;
    for (const Field& f : now)
        paths.push_back(f.section.toStdString() + "|" + f.path);
    if (paths != builtPaths_) {
        if (rebuildQueued_) return;
        rebuildQueued_ = true;
        QMetaObject::invokeMethod(this, [this] {
            if (rebuildQueued_) rebuild();
        }, Qt::QueuedConnection);
        return;
    }
    updating_ = true;
    for (const Field& f : now)
        if (const auto show = setters_.find(f.path); show != setters_.end()) show->second(f.value);
    updating_ = false;
}

void ScenePanel::addField(const Field& field) {
    const QString& label = field.label;
    const std::string& path = field.path;
    const nlohmann::json& value = field.value;
    const QString name = QString::fromStdString(path);
    auto commit = [this, path, name](const nlohmann::json& v) {
        QString error;
        updating_ = true;
        const bool ok = session_.editScene({path + "=" + v.dump()}, "set " + name, &error);
        updating_ = false;
        lastError_ = ok ? QString() : error;
        status_->setText(ok ? QString() : "<font color=#d55e00>" + error.toHtmlEscaped() + "</font>");
        // Refused: back to the project's value. Accepted: the rows may change (a type's parameters), rebuilt from the
        // event loop, never inside this field's own signal.
        refresh();
    };
    if (value.is_string() && !field.choices.isEmpty()) {
        auto* combo = new QComboBox;
        combo->setObjectName("scene:" + name);
        combo->addItems(field.choices);
        combo->setCurrentText(QString::fromStdString(value.get<std::string>()));
        // activated, not currentIndexChanged: only the user's choice is an edit, not the panel showing a value.
        connect(combo, &QComboBox::activated, this, [this, commit, combo](int) {
            if (!updating_) commit(combo->currentText().toStdString());
        });
        setters_[path] = [combo](const nlohmann::json& v) {
            const QSignalBlocker block(combo);
            combo->setCurrentText(QString::fromStdString(v.get<std::string>()));
        };
        form_->addRow(label, combo);
    } else if (value.is_number()) {
        auto* spin = value.is_number_integer() ? integerSpinBox(value.get<double>()) : spinBox(value.get<double>());
        spin->setObjectName("scene:" + name);
        connect(spin, &QDoubleSpinBox::valueChanged, this, [this, commit](double v) {
            if (!updating_) commit(v);
        });
        setters_[path] = [spin](const nlohmann::json& v) {
            const QSignalBlocker block(spin);
            spin->setValue(v.get<double>());
        };
        form_->addRow(label, spin);
    } else if (value.is_array() && value.size() == 3 && value[0].is_number()) {
        auto* row = new QWidget;
        row->setObjectName("scene:" + name);
        auto* layout = new QHBoxLayout(row);
        layout->setContentsMargins(0, 0, 0, 0);
        std::array<QDoubleSpinBox*, 3> spins{};
        for (int c = 0; c < 3; ++c) {
            spins[std::size_t(c)] = componentSpinBox(value[std::size_t(c)].get<double>());
            spins[std::size_t(c)]->setObjectName(QString("scene:%1[%2]").arg(name).arg(c));
            layout->addWidget(spins[std::size_t(c)]);
        }
        for (QDoubleSpinBox* s : spins)
            connect(s, &QDoubleSpinBox::valueChanged, this, [this, commit, spins](double) {
                if (!updating_) commit(nlohmann::json::array({spins[0]->value(), spins[1]->value(), spins[2]->value()}));
            });
        setters_[path] = [spins](const nlohmann::json& v) {
            for (std::size_t c = 0; c < 3; ++c) {
                const QSignalBlocker block(spins[c]);
                spins[c]->setValue(v[c].get<double>());
            }
        };
        form_->addRow(label, row);
    }
}

void ScenePanel::rebuild() {
    rebuildQueued_ = false;
    while (form_->rowCount() > 0)
        form_->removeRow(0);
    setters_.clear();
    builtPaths_.clear();
    for (const Field& f : fields()) {
        builtPaths_.push_back(f.section.toStdString() + "|" + f.path);
        if (f.path.empty())
            form_->addRow(new QLabel("<b>" + f.section.toHtmlEscaped() + "</b>"));
        else
            addField(f);
    }
    // What a Ctrl+click's impulse pushes with: the studio's, not the project's (each impulse stores its own).
    if (animation_ && animation_->available()) {
        form_->addRow(new QLabel("<b>Ctrl+click impulse</b>"));
        auto* radius = spinBox(animation_->impulseRadius());
        radius->setObjectName("scene:impulseRadius");
        radius->setRange(1e-3, 1e3);
        radius->setToolTip("m: particles closer than this to the click are pushed away");
        connect(radius, &QDoubleSpinBox::valueChanged, this, [this](double v) { animation_->setImpulseRadius(v); });
        form_->addRow("radius", radius);
        auto* speed = spinBox(animation_->impulseSpeed());
        speed->setObjectName("scene:impulseSpeed");
        speed->setRange(0.0, 1000.0);
        speed->setToolTip("m/s: the velocity given at the centre, falling linearly to 0 at the radius");
        connect(speed, &QDoubleSpinBox::valueChanged, this, [this](double v) { animation_->setImpulseSpeed(v); });
        form_->addRow("speed", speed);
    }
}

void ScenePanel::setAnimation(Animation* animation) {
    animation_ = animation;
    rebuild();
}

}  // namespace tyndall::studio
